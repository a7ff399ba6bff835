"""Engine throughput: agent-steps per second of the numba engine beside a plain numpy loop over agents.

Both run the paper scenario from the same seeded poses and fixed objectives
(the planner is left out so that the figure is the control step alone), in
the same process, one after the other. Prints a Markdown table.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from anicov.engine import advance_team, run_scenario
from anicov.run_parts import objective_fields
from bench.machine import describe_machine
from model.coverage_map import CoverageMap
from model.parameters import coverage_map_of, initial_poses, law_parameters, safety_parameters, starting_poses
from model.reachability import nearest_reachable
from model.reference import numpy_team_step
from model.run import TRACE_FIELDS
from model.safety import MEMORY_SIZE
from model.scenario import PAPER_SCENARIO, load_scenario
from model.world import world_of


def engine_rate(agents: int, steps: int, scenario_path: Path = PAPER_SCENARIO, **overrides: object) -> float:
    """Agent-steps/s of the engine's kernel on a scenario (a map: walls, bodies and occlusion included)."""
    scenario = load_scenario(scenario_path).with_overrides(agents=agents, seed=1, **overrides)
    world = world_of(scenario)
    coverage_map = coverage_map_of(scenario)
    law = law_parameters(scenario, coverage_map)
    poses = starting_poses(scenario)
    objectives = np.repeat(nearest_reachable(world.reachable, np.array([[50.0, 50.0]]), scenario.cell), agents, 0)
    fields = objective_fields(world, objectives)
    trace = np.zeros((steps, agents, len(TRACE_FIELDS)))
    errors = np.zeros(steps)
    flags = np.zeros((steps, agents), dtype=np.uint8)
    total = coverage_map.target_ticks * coverage_map.counted_cells
    safety, memory = safety_parameters(scenario), np.zeros((agents, MEMORY_SIZE), dtype=np.int64)

    def advance(coverage: np.ndarray, at: np.ndarray, count: int) -> int:
        done, _, _ = advance_team(
            coverage, at, objectives, law, world.ground, fields, safety, memory, count,
            coverage_map.uncovered_cells, coverage_map.deficit_ticks, total, trace, errors, flags,
        )  # fmt: skip
        return done

    advance(coverage_map.coverage.copy(), poses.copy(), 2)  # compile / load from cache
    started = time.perf_counter()
    done = advance(coverage_map.coverage, poses, steps)
    return done * agents / (time.perf_counter() - started)


def numpy_rate(agents: int, steps: int) -> float:
    scenario = load_scenario(PAPER_SCENARIO).with_overrides(agents=agents, seed=1)
    coverage_map = CoverageMap(*scenario.grid_shape, scenario.cell, scenario.lambda_star)
    law = law_parameters(scenario, coverage_map)
    poses = initial_poses(scenario)
    objectives = np.full((agents, 2), 50.0)
    numpy_team_step(coverage_map.coverage, poses, objectives, law)
    started = time.perf_counter()
    for _ in range(steps):
        numpy_team_step(coverage_map.coverage, poses, objectives, law)
    return steps * agents / (time.perf_counter() - started)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=3000, help="engine steps per team size")
    args = parser.parse_args()
    print(f"machine: {describe_machine()}")
    print("| team N | engine (numba) agent-steps/s | numpy loop agent-steps/s | speed-up |")
    print("|---|---|---|---|")
    for agents in (4, 30):
        fast = engine_rate(agents, args.steps)
        slow = numpy_rate(agents, max(20, args.steps // 100))
        print(f"| {agents} | {fast:,.0f} | {slow:,.0f} | {fast / slow:.0f}× |")
    print()
    print("| team N | empty domain | warehouse map, occlusion off | warehouse map, occlusion on | on / empty |")
    print("|---|---|---|---|---|")
    warehouse = PAPER_SCENARIO.parent / "warehouse.toml"
    for agents in (4, 10):
        empty = engine_rate(agents, args.steps)
        off = engine_rate(agents, args.steps, warehouse, occlusion=False, safety=False)
        on = engine_rate(agents, args.steps, warehouse, safety=False)
        print(f"| {agents} | {empty:,.0f} | {off:,.0f} | {on:,.0f} | {empty / on:.2f}× the cost |")

    print()
    safety_table(args.steps)


def run_rate(agents: int, seeds: int, **overrides: object) -> float:
    """Agent-steps/s of whole runs (planner and filter included) on the paper's domain, seeds 0.."""
    agent_steps, elapsed = 0, 0.0
    for seed in range(seeds):
        scenario = load_scenario(PAPER_SCENARIO).with_overrides(agents=agents, seed=seed, **overrides)
        poses = starting_poses(scenario.with_overrides(safety=True))  # the same start, filter on or off
        started = time.perf_counter()
        result = run_scenario(scenario, poses=poses, record_trace=False)
        elapsed += time.perf_counter() - started
        agent_steps += result.steps * agents
    return agent_steps / elapsed


def safety_table(steps: int) -> None:
    """Issue 12: the filter's cost, robots of radius 0.5 with s = 0.2, on the paper's domain."""
    print("| team N | filter off agent-steps/s | filter on agent-steps/s | cost | what runs |")
    print("|---|---|---|---|---|")
    body = {"robot_radius": 0.5, "safety_margin": 0.2}
    for agents in (4, 30):
        run_scenario(load_scenario(PAPER_SCENARIO).with_overrides(agents=agents, max_time=1.0, **body))  # compile
        off, on = run_rate(agents, 3, safety=False, **body), run_rate(agents, 3, **body)
        print(f"| {agents} | {off:,.0f} | {on:,.0f} | {off / on:.2f}× | whole runs, seeds 0-2 |")
        off = engine_rate(agents, steps, safety=False, **body)
        on = engine_rate(agents, steps, **body)
        print(f"| {agents} | {off:,.0f} | {on:,.0f} | {off / on:.2f}× | kernel, all sent to one point (a crowd) |")


if __name__ == "__main__":
    main()
