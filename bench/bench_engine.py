"""Engine throughput: agent-steps per second of the numba engine beside a plain numpy loop over agents.

Both run the paper scenario from the same seeded poses and fixed objectives
(the planner is left out so that the figure is the control step alone), in
the same process, one after the other. Prints Markdown tables: that one; the
warehouse map with fixed objectives; the kernel inside whole runs on each
shipped map against the empty domain (issue 11's cost of occlusion); the
safety filter's cost (issue 12); on the real maps, walls kept to the map's pixel against whole cells
(issue 34; ``--real-maps`` prints that table alone).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from anicov import engine
from anicov.engine import advance_team, run_scenario
from anicov.run_parts import objective_fields
from bench.machine import describe_machine
from model.controllers import law_parameters
from model.paper.coverage_map import CoverageMap
from model.parameters import coverage_map_of, initial_poses, safety_parameters, starting_poses
from model.reference import numpy_team_step
from model.run import TRACE_FIELDS
from model.safety.safety import MEMORY_SIZE
from model.scenario import PAPER_SCENARIO, ScenarioError, load_scenario
from model.world.reachability import nearest_reachable
from model.world.world import world_of

REPEATS = 3
"""Each engine rate is the best of this many timings of the same steps from the same start: this VM's
speed moves a single timing by up to 10 %, and the fastest is the one least disturbed by other work."""


def engine_rate(agents: int, steps: int, scenario_path: Path = PAPER_SCENARIO, **overrides: object) -> float:
    """Agent-steps/s of the engine's kernel on a scenario (a map: walls, bodies and occlusion included), the
    best of REPEATS timings."""
    return engine_rates_in_turn(agents, steps, (scenario_path, overrides), repeats=REPEATS)[0]


COMPARED_REPEATS = 10
"""Rates set side by side for a ratio (the occlusion and filter tables) are timed in turn, one timing of each
per round, and each kept as its best of this many rounds: the VM's speed drifts between timings, and a
ratio of rates timed one after the other took that drift in (the empty domain's rate moved 191,000 -
227,000 between runs, which was most of the fixed-point ratio's spread)."""


def engine_rates_in_turn(
    agents: int, steps: int, *configurations: tuple[Path, dict[str, object]], repeats: int = COMPARED_REPEATS
) -> list[float]:
    """:func:`engine_rate` of each (scenario path, overrides), timed in turn, best of ``repeats`` rounds."""
    best = [0.0] * len(configurations)
    for _ in range(repeats):
        for k, (path, overrides) in enumerate(configurations):
            best[k] = max(best[k], _engine_rate_once(agents, steps, path, **overrides))
    return best


def _engine_rate_once(agents: int, steps: int, scenario_path: Path, **overrides: object) -> float:
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
    looks = np.full((agents, 2), np.nan)

    def advance(coverage: np.ndarray, at: np.ndarray, count: int) -> int:
        done, _, _ = advance_team(
            coverage, at, objectives, law, world.ground, fields, safety, memory, looks, 0, count,
            coverage_map.uncovered_cells, coverage_map.deficit_ticks, total, trace, errors, flags,
        )  # fmt: skip
        return done

    advance(coverage_map.coverage.copy(), poses.copy(), 2)  # compile / load from cache
    looks.fill(np.nan)  # the timed run starts as the warm-up did
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
    parser.add_argument("--real-maps", action="store_true", help="only the real maps' wall-detail table")
    args = parser.parse_args()
    print(f"machine: {describe_machine()}")
    if args.real_maps:
        wall_detail_table()
        return
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
        empty, off, on = engine_rates_in_turn(
            agents,
            args.steps,
            (PAPER_SCENARIO, {}),
            (warehouse, {"occlusion": False, "safety": False}),
            (warehouse, {"safety": False}),
        )
        print(f"| {agents} | {empty:,.0f} | {off:,.0f} | {on:,.0f} | {empty / on:.2f}× the cost |")

    print()
    terrain_in_runs_table()
    print()
    safety_table(args.steps)
    print()
    wall_detail_table()


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


@contextmanager
def kernel_clock() -> Iterator[list[float]]:
    """Time spent in the engine's control kernel (``advance_team``) and agent-steps it made, as [seconds,
    agent-steps], while the block runs: the planner, the fields and the bookkeeping are left out."""
    totals = [0.0, 0.0]
    kernel = engine.advance_team

    def timed(*args: object) -> tuple[int, int, int]:
        started = time.perf_counter()
        done = kernel(*args)
        totals[0] += time.perf_counter() - started
        totals[1] += done[0] * args[1].shape[0]  # steps done x agents (args[1]: the poses)
        return done

    engine.advance_team = timed
    try:
        yield totals
    finally:
        engine.advance_team = kernel


def kernel_rate_in_runs(scenario_path: Path, agents: int, seeds: int, **overrides: object) -> float:
    """Agent-steps/s of the control kernel over whole runs (seeds 0..), objectives from Algorithms 1-2."""
    run_scenario(load_scenario(scenario_path).with_overrides(agents=agents, max_time=1.0, **overrides))  # compile
    with kernel_clock() as totals:
        for seed in range(seeds):
            scenario = load_scenario(scenario_path).with_overrides(agents=agents, seed=seed, **overrides)
            run_scenario(scenario, record_trace=False)
    return totals[1] / totals[0]


def terrain_in_runs_table(seeds: int = 3) -> None:
    """Issue 11's cost in the state runs are in: the kernel over whole runs on each shipped map (robots of
    radius 0.4, no filter, as docs/terrain measures them) against the empty domain's, same N and seeds.
    The fixed-objective table above sends every robot to one point, which is covered within a minute;
    from then on every robot stands and searches R for an uncovered cell in sight, every step, a state a
    run leaves at its next replan (Algorithm 1 drops an objective whose cell is covered)."""
    print(
        f"| team N | map | empty domain agent-steps/s | occlusion off | occlusion on | on / empty | whole runs, seeds 0-{seeds - 1} |"
    )
    print("|---|---|---|---|---|---|---|")
    for agents in (4, 10):
        empty = kernel_rate_in_runs(PAPER_SCENARIO, agents, seeds)
        for name in ("warehouse", "office", "field"):
            path = PAPER_SCENARIO.parent / f"{name}.toml"
            off = kernel_rate_in_runs(path, agents, seeds, occlusion=False, safety=False)
            on = kernel_rate_in_runs(path, agents, seeds, safety=False)
            print(
                f"| {agents} | {name} | {empty:,.0f} | {off:,.0f} | {on:,.0f} | {empty / on:.2f}× the cost | kernel only |"
            )


def wall_detail_table(seeds: int = 3, agents: int = 4) -> None:
    """Issue 34: the kernel over whole runs on each real map (scenarios/real, fetched by ./go maps), the filter
    on, with walls kept to the map's pixel (``wall_detail = "map"``, the default) against whole cells."""
    print(f"| map | N | walls to whole cells, agent-steps/s | to the pixel | cost | whole runs, seeds 0-{seeds - 1} |")
    print("|---|---|---|---|---|---|")
    for name in ("uwb-lab", "malaga-campus"):
        path = PAPER_SCENARIO.parent / "real" / f"{name}.toml"
        try:
            load_scenario(path)
        except ScenarioError as error:  # the map is not fetched: say so, measure the rest
            print(f"| {name} | {agents} | – | – | – | not measured: {error} |")
            continue
        cells = kernel_rate_in_runs(path, agents, seeds, wall_detail="cell")
        pixels = kernel_rate_in_runs(path, agents, seeds)
        print(f"| {name} | {agents} | {cells:,.0f} | {pixels:,.0f} | {cells / pixels:.2f}× | kernel only |")


def safety_table(steps: int) -> None:
    """Issue 12: the filter's cost, robots of radius 0.5 with s = 0.2, on the paper's domain."""
    print("| team N | filter off agent-steps/s | filter on agent-steps/s | cost | what runs |")
    print("|---|---|---|---|---|")
    body = {"robot_radius": 0.5, "safety_margin": 0.2}
    for agents in (4, 30):
        run_scenario(load_scenario(PAPER_SCENARIO).with_overrides(agents=agents, max_time=1.0, **body))  # compile
        off, on = run_rate(agents, 3, safety=False, **body), run_rate(agents, 3, **body)
        print(f"| {agents} | {off:,.0f} | {on:,.0f} | {off / on:.2f}× | whole runs, seeds 0-2 |")
        off, on = engine_rates_in_turn(
            agents, steps, (PAPER_SCENARIO, {"safety": False, **body}), (PAPER_SCENARIO, body)
        )
        print(f"| {agents} | {off:,.0f} | {on:,.0f} | {off / on:.2f}× | kernel, all sent to one point (a crowd) |")


if __name__ == "__main__":
    main()
