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

from anicov.engine import advance_team
from bench.machine import describe_machine
from model.coverage_map import CoverageMap
from model.parameters import initial_poses, law_parameters
from model.reference import numpy_team_step
from model.run import TRACE_FIELDS
from model.scenario import PAPER_SCENARIO, load_scenario


def engine_rate(agents: int, steps: int) -> float:
    scenario = load_scenario(PAPER_SCENARIO).with_overrides(agents=agents, seed=1)
    coverage_map = CoverageMap(*scenario.grid_shape, scenario.cell, scenario.lambda_star)
    law = law_parameters(scenario, coverage_map)
    poses = initial_poses(scenario)
    objectives = np.full((agents, 2), 50.0)
    trace = np.zeros((steps, agents, len(TRACE_FIELDS)))
    errors = np.zeros(steps)
    advance_team(
        coverage_map.coverage.copy(),
        poses.copy(),
        objectives,
        law,
        2,
        coverage_map.uncovered_cells,
        coverage_map.deficit_ticks,
        trace,
        errors,
    )  # compile / load from cache
    started = time.perf_counter()
    done, _, _ = advance_team(
        coverage_map.coverage,
        poses,
        objectives,
        law,
        steps,
        coverage_map.uncovered_cells,
        coverage_map.deficit_ticks,
        trace,
        errors,
    )
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


if __name__ == "__main__":
    main()
