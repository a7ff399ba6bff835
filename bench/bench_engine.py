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

from anicov.engine import advance_team, objective_fields
from bench.machine import describe_machine
from model.coverage_map import CoverageMap
from model.parameters import coverage_map_of, initial_poses, law_parameters, starting_poses
from model.reachability import nearest_reachable
from model.reference import numpy_team_step
from model.run import TRACE_FIELDS
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
    total = coverage_map.target_ticks * coverage_map.counted_cells

    def advance(coverage: np.ndarray, at: np.ndarray, count: int) -> int:
        done, _, _ = advance_team(
            coverage, at, objectives, law, world.ground, fields, count,
            coverage_map.uncovered_cells, coverage_map.deficit_ticks, total, trace, errors,
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
        off = engine_rate(agents, args.steps, warehouse, occlusion=False)
        on = engine_rate(agents, args.steps, warehouse)
        print(f"| {agents} | {empty:,.0f} | {off:,.0f} | {on:,.0f} | {empty / on:.2f}× the cost |")


if __name__ == "__main__":
    main()
