"""model.physics.world: robots on wheels in MuJoCo, against eq. 1; contacts counted; runs that repeat bit for bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model.paper.dynamics import unicycle_step
from model.physics.base import base_of
from model.physics.world import PhysicsWorld
from model.scenario import validate
from model.world.world import world_of

BURGER = {"domain": [10.0, 10.0], "robot_radius": 0.105, "k_v": 0.22, "k_omega": 0.904, "physics": "mujoco"}


def world_of_robots(poses, **values) -> tuple[PhysicsWorld, float]:
    scenario = validate({**BURGER, "agents": len(poses), **values})
    base = base_of(scenario)
    return PhysicsWorld(scenario.domain, world_of(scenario).ground, base, np.array(poses), scenario.dt), scenario.dt


def commands_held_for_ten_periods(seed: int = 0) -> list[tuple[float, float]]:
    """Random (v, ω) within the Burger's bounds (0.22 m/s, 2.84 rad/s), each held for 10 periods."""
    rng = np.random.default_rng(seed)
    held = [(rng.uniform(0.0, 0.22), rng.uniform(-2.8, 2.8)) for _ in range(20)]
    return [command for command in held for _ in range(10)]


def tracking_errors(world: PhysicsWorld, dt: float, commands) -> tuple[np.ndarray, np.ndarray]:
    """Per period: how far the world's pose is from eq. 1's from the period's start pose (position, heading)."""
    pose, position, heading = world.poses()[0], [], []
    for v, omega in commands:
        wanted = unicycle_step(*pose, v, omega, dt)
        pose = world.step(np.array([[v, omega]]))[0]
        position.append(math.hypot(pose[0] - wanted[0], pose[1] - wanted[1]))
        heading.append(abs((pose[2] - wanted[2] + math.pi) % (2.0 * math.pi) - math.pi))
    return np.array(position), np.array(heading)


def test_with_a_high_torque_limit_a_robot_tracks_eq_1():
    """Measured (Burger sizes, acceleration 1,000 m/s²): held periods after the change of command within
    0.08 mm and 1e-5 rad of eq. 1 per 0.1 s period; the period of a change is bounded by the wheels' grip
    (μ g), not the motors: at most 15 mm and 0.26 rad for a step of 5.6 rad/s in ω."""
    world, dt = world_of_robots([[5.0, 5.0, 0.0]], robot={"acceleration": 1000.0})
    position, heading = tracking_errors(world, dt, commands_held_for_ten_periods())
    held = np.arange(len(position)) % 10 >= 2
    assert position[held].max() < 0.2e-3 and heading[held].max() < 1e-3
    assert position.max() < 0.03 and heading.max() < 0.4


def test_with_a_low_torque_limit_a_robot_lags_as_its_acceleration_says():
    """From rest at v = k_v = 0.22 m/s with 0.3 m/s² of acceleration: 0.73 s to full speed, so after 1 s it has
    come 0.22 − 0.22² / 0.6 = 0.139 m, not eq. 1's 0.22 m."""
    world, _ = world_of_robots([[5.0, 5.0, 0.0]], robot={"acceleration": 0.3})
    for _ in range(10):
        pose = world.step(np.array([[0.22, 0.0]]))[0]
    assert pose[0] - 5.0 == pytest.approx(0.22 - 0.22**2 / 0.6, rel=0.05)
    assert abs(pose[1] - 5.0) < 1e-6 and abs(pose[2]) < 1e-6


def test_two_robots_driven_into_each_other_make_one_contact_the_world_counts():
    """No filter here: two robots 0.5 m apart drive at each other; they touch once, and stay touching."""
    world, _ = world_of_robots([[4.75, 5.0, 0.0], [5.25, 5.0, math.pi]])
    assert world.contacts.total == 0
    for _ in range(30):
        world.step(np.array([[0.22, 0.0], [0.22, 0.0]]))
    assert world.contacts.robots == 1 and world.contacts.walls == 0
    assert world.contacts.touching == {(0, 1)}
    gap = np.linalg.norm(world.poses()[0, :2] - world.poses()[1, :2])
    assert gap < 2.0 * 0.105 + 0.01  # bodies pressed together, not through each other


def test_a_robot_driven_into_a_wall_makes_a_wall_contact():
    world, _ = world_of_robots([[5.0, 5.0, 0.0]], obstacles=[[[6.0, 3.0], [7.0, 3.0], [7.0, 7.0], [6.0, 7.0]]])
    for _ in range(60):
        world.step(np.array([[0.22, 0.0]]))
    assert world.contacts.walls == 1 and world.contacts.robots == 0
    assert world.poses()[0, 0] < 6.0 - 0.105 + 0.01  # stopped by the wall


def test_the_same_commands_give_the_same_poses_bit_for_bit():
    runs = []
    for _ in range(2):
        world, _ = world_of_robots([[3.0, 3.0, 0.0], [6.0, 6.0, 1.0]])
        for v, omega in commands_held_for_ten_periods(seed=3)[:60]:
            poses = world.step(np.array([[v, omega], [v, -omega]]))
        runs.append(poses.tobytes())
    assert runs[0] == runs[1]
