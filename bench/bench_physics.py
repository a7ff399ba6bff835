"""The physics world's speed (issue 37): real-time factor of MuJoCo stepping N robots on the lab map, and the
agent-step rate of whole physics runs against the kinematic engine's.

    .venv/bin/python bench/bench_physics.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from anicov.engine import run_scenario
from bench.machine import describe_machine
from model.parameters import starting_poses
from model.physics.base import base_of
from model.physics.world import PhysicsWorld
from model.scenario import load_scenario, validate
from model.world.world import world_of

LAB = Path(__file__).resolve().parent.parent / "scenarios" / "real" / "uwb-lab.toml"
PERIODS = 200


def real_time_factor(agents: int) -> float:
    """Simulated seconds per wall second, N robots on the lab map driving circles (no planning, no sensing)."""
    scenario = load_scenario(LAB).with_overrides(agents=agents, physics="mujoco")
    world = PhysicsWorld(scenario.domain, world_of(scenario).ground, base_of(scenario), starting_poses(scenario), 0.1)
    commands = np.tile([0.1, 0.5], (agents, 1))
    world.step(commands)
    started = time.perf_counter()
    for _ in range(PERIODS):
        world.step(commands)
    return PERIODS * scenario.dt * scenario.seconds_per_unit / (time.perf_counter() - started)


def agent_steps_per_second(physics: str) -> tuple[float, float]:
    """(agent-steps per wall second, completion time) of a whole run: two rooms and a door, N = 4, anicov."""
    scenario = validate({
        "domain": [24.0, 16.0], "cell": 1.0, "range": 5.0, "robot_radius": 0.4, "agents": 4, "seed": 2,
        "controller": "anicov", "physics": physics,
        "obstacles": [[[12.0, 0.0], [13.0, 0.0], [13.0, 6.0], [12.0, 6.0]],
                      [[12.0, 10.0], [13.0, 10.0], [13.0, 16.0], [12.0, 16.0]]],
    })  # fmt: skip
    run_scenario(scenario)  # numba's kernels and the stations' layouts loaded before timing
    started = time.perf_counter()
    result = run_scenario(scenario)
    return result.steps * scenario.agents / (time.perf_counter() - started), result.completion_time


def main() -> None:
    print(f"machine: {describe_machine()}")
    print("| robots on the lab map | real-time factor (physics step 2 ms, 50 a period) |")
    print("|---|---|")
    for agents in (4, 10, 30):
        print(f"| {agents} | {real_time_factor(agents):.1f}x |")
    print("| whole run, two rooms and a door, N = 4, anicov | agent-steps/s | completion time |")
    print("|---|---|---|")
    for physics in ("kinematic", "mujoco"):
        rate, completion = agent_steps_per_second(physics)
        print(f"| {physics} | {rate:,.0f} | {completion:.1f} |")


if __name__ == "__main__":
    main()
