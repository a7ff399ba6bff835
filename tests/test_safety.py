"""The safety filter alone (model.safety.safety): for any states and nominal commands, the filtered command keeps
the paper's velocity bounds and every barrier's discrete-time condition h_{k+1} ≥ (1 − γ)·h_k."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from model.paper.dynamics import unicycle_step
from model.parameters import safety_parameters
from model.safety.safety import (
    DEADLOCK_FOUND,
    DEADLOCK_RESOLVED,
    FILTER_CHANGED,
    KEEPING_RIGHT,
    MEMORY_SIZE,
    NO_SAFE_COMMAND,
    PARKED,
    STALE_NEIGHBOUR,
    TEAMMATE,
    filter_command,
)
from model.scenario import load_scenario, validate
from model.world.ground import open_ground
from model.world.world import world_of
from tests.test_real_maps import REAL, map_of

SCENARIO = validate({"agents": 2, "robot_radius": 0.5, "safety_margin": 0.2})
SAFETY = safety_parameters(SCENARIO)
GROUND = open_ground()
V_MAX, OMEGA_MAX = SCENARIO.k_v, math.pi * SCENARIO.k_omega
POINTS_APART = 2 * SAFETY.radius + SAFETY.margin + 2 * SAFETY.lookahead  # D of the pair barrier

headings = st.floats(-math.pi, math.pi)
speeds = st.floats(-V_MAX, V_MAX)
turns = st.floats(-OMEGA_MAX, OMEGA_MAX)


def point(pose: np.ndarray) -> np.ndarray:
    return pose[:2] + SAFETY.lookahead * np.array([math.cos(pose[2]), math.sin(pose[2])])


def filtered(poses: np.ndarray, nominal: list[tuple[float, float]], kinds: np.ndarray | None = None) -> list:
    kinds = np.full(len(poses), TEAMMATE) if kinds is None else kinds
    ages = np.zeros(len(poses))
    return [
        filter_command(
            v, w, i, poses, ages, kinds, GROUND, SCENARIO.cell, SAFETY, np.zeros(MEMORY_SIZE, dtype=np.int64)
        )
        for i, (v, w) in enumerate(nominal)
    ]


@st.composite
def pairs(draw: st.DrawFn) -> np.ndarray:
    """Two poses whose look-ahead points are at least D apart (the barrier holds), often just so."""
    gap = draw(st.one_of(st.floats(0.0, 0.05), st.floats(0.0, 3.0)))
    bearing = draw(headings)
    first = np.array([10.0, 10.0, draw(headings)])
    a = point(first)
    b = a + (POINTS_APART + gap) * np.array([math.cos(bearing), math.sin(bearing)])
    theta = draw(headings)
    second = np.array([b[0] - SAFETY.lookahead * math.cos(theta), b[1] - SAFETY.lookahead * math.sin(theta), theta])
    return np.stack([first, second])


@settings(max_examples=1500, deadline=None)
@given(pairs(), speeds, turns, speeds, turns)
def test_a_pair_keeps_the_barrier_and_the_bounds(poses: np.ndarray, v0: float, w0: float, v1: float, w1: float) -> None:
    commands = filtered(poses, [(v0, w0), (v1, w1)])
    after = []
    for pose, (v, omega, _) in zip(poses, commands, strict=True):
        assert abs(v) <= V_MAX + 1e-9 and abs(omega) <= OMEGA_MAX + 1e-9
        after.append(np.array(unicycle_step(*pose, v, omega, SCENARIO.dt)))
    h_before = np.linalg.norm(point(poses[0]) - point(poses[1])) - POINTS_APART
    h_after = np.linalg.norm(point(after[0]) - point(after[1])) - POINTS_APART
    assert h_after >= (1.0 - SAFETY.decay) * h_before - 1e-9
    assert np.linalg.norm(after[0][:2] - after[1][:2]) >= 2 * SAFETY.radius + SAFETY.margin - 1e-9


@settings(max_examples=500, deadline=None)
@given(pairs(), speeds, turns, speeds, turns)
def test_a_parked_teammate_is_avoided_alone(poses: np.ndarray, v0: float, w0: float, v1: float, w1: float) -> None:
    """A teammate whose process died does not move: the robot takes the whole constraint."""
    (v, omega, _), _ = filtered(poses, [(v0, w0), (0.0, 0.0)], np.array([TEAMMATE, PARKED]))
    moved = np.array(unicycle_step(*poses[0], v, omega, SCENARIO.dt))
    h_before = np.linalg.norm(point(poses[0]) - point(poses[1])) - POINTS_APART
    h_after = np.linalg.norm(point(moved) - point(poses[1])) - POINTS_APART
    assert h_after >= (1.0 - SAFETY.decay) * h_before - 1e-9


def test_a_command_nobody_constrains_is_unchanged() -> None:
    poses = np.array([[10.0, 10.0, 0.0], [30.0, 10.0, math.pi]])
    assert filtered(poses, [(0.7, 0.3), (1.0, -2.0)]) == [(0.7, 0.3, 0), (1.0, -2.0, 0)]


def test_head_on_robots_slow_down_and_the_change_is_flagged() -> None:
    poses = np.array([[10.0, 10.0, 0.0], [10.0 + POINTS_APART + 2 * SAFETY.lookahead + 0.3, 10.0, math.pi]])
    (v0, _, flags0), (v1, _, flags1) = filtered(poses, [(1.0, 0.0), (1.0, 0.0)])
    assert 0.0 < v0 < 1.0 and 0.0 < v1 < 1.0
    assert flags0 & FILTER_CHANGED and flags1 & FILTER_CHANGED


def test_a_stale_teammate_in_range_stops_the_robot() -> None:
    poses = np.array([[10.0, 10.0, 0.0], [13.0, 10.0, math.pi]])
    ages = np.array([0.0, SAFETY.max_pose_age + 0.01])
    kinds = np.array([TEAMMATE, TEAMMATE])
    memory = np.zeros(MEMORY_SIZE, dtype=np.int64)
    assert filter_command(1.0, 0.0, 0, poses, ages, kinds, GROUND, 1.0, SAFETY, memory) == (0.0, 0.0, STALE_NEIGHBOUR)
    far = np.array([[10.0, 10.0, 0.0], [40.0, 10.0, math.pi]])
    assert filter_command(1.0, 0.0, 0, far, ages, kinds, GROUND, 1.0, SAFETY, memory) == (1.0, 0.0, 0)


def test_an_old_pose_widens_the_margin() -> None:
    """A pose younger than max_pose_age: the clearance grows by how far the teammate's point can have gone."""
    gap = POINTS_APART + 2 * SAFETY.lookahead + 0.3
    poses = np.array([[10.0, 10.0, 0.0], [10.0 + gap, 10.0, math.pi]])
    kinds, memory = np.array([TEAMMATE, TEAMMATE]), np.zeros(MEMORY_SIZE, dtype=np.int64)
    fresh = filter_command(1.0, 0.0, 0, poses, np.zeros(2), kinds, GROUND, 1.0, SAFETY, memory)
    aged = filter_command(1.0, 0.0, 0, poses, np.array([0.0, 0.4]), kinds, GROUND, 1.0, SAFETY, memory)
    assert aged[0] < fresh[0]


def test_a_deadlock_is_found_then_resolved_by_keeping_right() -> None:
    """Two robots head-on, each driven straight at the other: the filter alone holds both still; after
    STUCK_STEPS each turns to its right, they pass, and the straight command passes the filter again."""
    poses = np.array([[10.0, 10.0, 0.0], [16.0, 10.0, math.pi]])
    goals = np.array([[22.0, 10.0], [4.0, 10.0]])
    memory = np.zeros((2, MEMORY_SIZE), dtype=np.int64)
    seen = 0
    closest = math.inf
    for _ in range(600):
        commands = []
        for i in range(2):
            heading = math.atan2(goals[i, 1] - poses[i, 1], goals[i, 0] - poses[i, 0])
            error = math.remainder(heading - poses[i, 2], math.tau)
            v_hat, w_hat = V_MAX * max(0.0, math.cos(error)), OMEGA_MAX / math.pi * error
            commands.append(
                filter_command(
                    v_hat,
                    w_hat,
                    i,
                    poses,
                    np.zeros(2),
                    np.zeros(MEMORY_SIZE, dtype=np.int64),
                    GROUND,
                    1.0,
                    SAFETY,
                    memory[i],
                )
            )
        seen |= commands[0][2] | commands[1][2]
        poses = np.array([unicycle_step(*poses[i], commands[i][0], commands[i][1], SCENARIO.dt) for i in range(2)])
        closest = min(closest, float(np.linalg.norm(poses[0, :2] - poses[1, :2])))
    assert seen & DEADLOCK_FOUND and seen & DEADLOCK_RESOLVED
    assert np.linalg.norm(poses[:, :2] - goals, axis=1).max() < 0.5
    assert closest >= 2 * SAFETY.radius + SAFETY.margin - 1e-9


def test_a_robot_driven_into_a_wall_keeps_the_margin_and_slides_along_it() -> None:
    """The law drives straight at a wall: the filter brings the disk to s off it, never nearer, and
    then slides it along the wall (to its right, head-on) instead of leaving it there."""
    scenario = validate(
        {
            "agents": 1,
            "robot_radius": 0.5,
            "domain": [20.0, 20.0],
            "obstacles": [[[12, 0], [13, 0], [13, 20], [12, 20]]],
        }
    )
    ground, safety = world_of(scenario).ground, safety_parameters(scenario)
    pose = np.array([[8.0, 10.0, 0.0]])
    memory = np.zeros(MEMORY_SIZE, dtype=np.int64)
    gaps = []
    for _ in range(200):
        v, omega, _ = filter_command(
            1.0, 0.0, 0, pose, np.zeros(1), np.zeros(1, dtype=np.int64), ground, 1.0, safety, memory
        )
        pose[0] = unicycle_step(*pose[0], v, omega, scenario.dt)
        gaps.append(12.0 - pose[0, 0])
    least = safety.radius + safety.margin
    assert min(gaps) >= least - 1e-9 and min(gaps) < least + 0.05
    assert pose[0, 1] < 10.0 - 3.0  # slid down the wall, to its right


WALLED = validate(
    {"agents": 1, "robot_radius": 0.5, "domain": [20.0, 20.0], "obstacles": [[[9, 9], [11, 9], [11, 11], [9, 11]]]}
)
WALLED_GROUND, WALLED_SAFETY = world_of(WALLED).ground, safety_parameters(WALLED)


def wall_gap(x: float, y: float) -> float:
    """Distance from a centre to the block [9, 11]², less r + s (the wall barrier h)."""
    dx, dy = max(9.0 - x, 0.0, x - 11.0), max(9.0 - y, 0.0, y - 11.0)
    return math.hypot(dx, dy) - WALLED_SAFETY.radius - WALLED_SAFETY.margin


@settings(max_examples=1500, deadline=None)
@given(st.floats(7.8, 12.2), st.floats(7.8, 12.2), headings, speeds, turns)
def test_a_wall_keeps_its_barrier(x: float, y: float, theta: float, v_hat: float, w_hat: float) -> None:
    """Any pose by a square block (sides and corners, 0 to 0.5 from the barrier), any command:
    h_{k+1} ≥ (1 − γ)·h_k, and the paper's bounds kept."""
    h = wall_gap(x, y)
    assume(h >= 0.0)
    pose = np.array([[x, y, theta]])
    memory = np.zeros(MEMORY_SIZE, dtype=np.int64)
    v, omega, _ = filter_command(
        v_hat, w_hat, 0, pose, np.zeros(1), np.zeros(1, dtype=np.int64), WALLED_GROUND, 1.0, WALLED_SAFETY, memory
    )
    assert abs(v) <= V_MAX + 1e-9 and abs(omega) <= OMEGA_MAX + 1e-9
    after = unicycle_step(x, y, theta, v, omega, WALLED.dt)
    assert wall_gap(after[0], after[1]) >= (1.0 - WALLED_SAFETY.decay) * h - 1e-9


def test_a_robot_inside_a_wall_s_margin_along_the_wall_turns_out_instead_of_standing_for_good() -> None:
    """A centre put inside the margin (a belief off the truth, a late command) nearly along the wall: no v gets it
    out at the barrier's rate, and the filter used to stop it, v = ω = 0, at every step (two rooms with the
    issue's noise: for the rest of the run). Asked only not to go deeper, it turns and leaves, never deeper."""
    pose = np.array([[11.0 + 0.9 * (WALLED_SAFETY.radius + WALLED_SAFETY.margin), 10.0, math.pi / 2 + 0.05]])
    memory = np.zeros(MEMORY_SIZE, dtype=np.int64)
    gaps, stopped = [wall_gap(pose[0, 0], pose[0, 1])], 0
    assert gaps[0] < 0.0
    for _ in range(100):  # the law drives on along the wall, as a carrot ahead asks
        v, omega, flags = filter_command(
            1.0, 0.0, 0, pose, np.zeros(1), np.zeros(1, dtype=np.int64), WALLED_GROUND, 1.0, WALLED_SAFETY, memory
        )
        stopped += bool(flags & NO_SAFE_COMMAND)
        pose[0] = unicycle_step(*pose[0], v, omega, WALLED.dt)
        gaps.append(wall_gap(pose[0, 0], pose[0, 1]))
    assert stopped == 0
    assert min(gaps) >= gaps[0] - 1e-9  # never deeper
    assert gaps[-1] >= 0.0 and pose[0, 1] > 11.0  # out of the margin, on along the wall past the block


def test_a_teammate_held_again_and_again_yields_to_a_robot_hemmed_by_a_wall() -> None:
    """The lab map's state where two robots stood for the rest of a run (N = 8 seed 19, t = 800): robot 1
    turns in place with a wall ahead, each turn toward its way swinging its look-ahead point at robot 0's,
    which drives slowly to its objective next to robot 1. Robot 0's deadlock was "resolved" by keeping right
    a step after it was found and found again ten steps later, for good; robot 1 never came within 50° of
    its way. On that relapse robot 0 yields (the lower id), and robot 1 comes to face its way."""
    map_of(REAL / "uwb-lab.toml")  # fetched, or skipped (failed under CI)
    scenario = load_scenario(REAL / "uwb-lab.toml").with_overrides(agents=2)
    ground, safety = world_of(scenario).ground, safety_parameters(scenario)
    poses = np.array([[10.187, 8.881, -0.902], [10.308, 8.426, -1.355]])  # the run's frame (not the map's)
    goals = np.array([[10.30, 8.70], [9.90, 8.10]])
    memory = np.zeros((2, MEMORY_SIZE), dtype=np.int64)
    flags, least_error, closest = np.zeros(2, dtype=np.int64), math.inf, math.inf
    for _ in range(1000):
        commands = []
        for i in range(2):
            error = math.remainder(
                math.atan2(goals[i, 1] - poses[i, 1], goals[i, 0] - poses[i, 0]) - poses[i, 2], math.tau
            )
            if i == 0:  # its last stretch, slowly (about 0.03 m/s there, as the run's law)
                distance = float(np.linalg.norm(goals[i] - poses[i, :2]))
                v_hat, w_hat = 0.15 * distance * max(0.0, math.cos(error)), scenario.k_omega * error
            else:  # turning in place to its way (about 1.3 rad/s there, as the run's law)
                v_hat, w_hat = 0.0, 1.2 * error
            alone = np.zeros(2), np.zeros(2, dtype=np.int64)  # lockstep poses, both teammates
            commands.append(filter_command(v_hat, w_hat, i, poses, *alone, ground, scenario.cell, safety, memory[i]))
            flags[i] |= commands[i][2]
            if i == 1:
                least_error = min(least_error, abs(error))
        poses = np.array([unicycle_step(*poses[i], *commands[i][:2], scenario.dt) for i in range(2)])
        closest = min(closest, float(np.linalg.norm(poses[0, :2] - poses[1, :2])))
    assert flags[0] & DEADLOCK_FOUND and flags[0] & KEEPING_RIGHT  # robot 0 kept right, then yielded
    assert least_error < math.radians(15.0)
    assert closest >= 2 * safety.radius + safety.margin - 1e-9
