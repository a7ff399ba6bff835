"""How long the anicov controller's first plan takes, with stations (its default): the stations' layouts
(model.controllers.anicov.stations.layout: the linear programme for each spacing and both serpentines, once per process and
scenario, timed on its own), then per team the serpentine cut for the robots on its 8 symmetries and the
order searched on the 2 soonest (model.controllers.anicov.piece_order), the routes flown until they leave nothing short or
twice patched (periods put in where they fall short), the last flight read for the orbits over what is left
(model.controllers.anicov.touch_ups). In
realtime the team waits this long for its first carrots; in lockstep and in the engine it is paid once per
run. Issue 36's goals: at most 2 s at N = 100 on the paper's square, at most 10 s on the largest map of the
corpus (``--maps``: the lab hall and the Málaga campus, fetched by ``./go maps``; among walls the first plan is
the stations' programme, once per process and domain, then per team the tour, its shares and its stares beside
the hops, :mod:`model.controllers.anicov.terrain_plan`).

    .venv/bin/python bench/bench_planner.py
    .venv/bin/python bench/bench_planner.py --maps
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bench.machine import describe_machine
from model.controllers.anicov.lane_planner import LanePlanner
from model.controllers.anicov.stations import forget_layouts, layout
from model.parameters import starting_poses
from model.scenario import load_scenario
from model.world.world import world_of

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"
CASES = [
    ("paper.toml", 1),
    ("paper.toml", 4),
    ("paper.toml", 10),
    ("paper.toml", 30),
    ("paper.toml", 100),
    ("wide.toml", 1),
    ("wide.toml", 30),
]
SEEDS = (0, 1, 2)
MAP_CASES = [
    ("real/uwb-lab.toml", 1),
    ("real/uwb-lab.toml", 8),
    ("real/malaga-campus.toml", 1),
    ("real/malaga-campus.toml", 8),
    ("real/malaga-campus.toml", 30),
]


def first_plan_seconds(config: str, agents: int, seed: int) -> tuple[float, int]:
    """(seconds of the first plan, orbits planned) for one team's random start."""
    scenario = load_scenario(SCENARIOS / config).with_overrides(controller="anicov", agents=agents, seed=seed)
    planner = LanePlanner(scenario)
    positions = starting_poses(scenario)[:, :2]
    started = time.perf_counter()
    planner.plan(np.ones(scenario.grid_shape), positions)
    return time.perf_counter() - started, sum(len(touch_ups) for touch_ups in planner.touch_ups.values())


def layout_seconds(config: str) -> float:
    """Seconds of the stations' layouts of one scenario (both serpentines), computed afresh (every layout
    computed before is forgotten)."""
    scenario = load_scenario(SCENARIOS / config).with_overrides(controller="anicov")
    forget_layouts()
    started = time.perf_counter()
    for by_columns in (False, True):
        layout(scenario, by_columns)
    return time.perf_counter() - started


def map_first_plans(config: str, agents: int) -> tuple[float, list[float]]:
    """(seconds of the first team's first plan in a fresh process, the stations' programme included; seconds of
    the next teams', seeds 1 - 2), the world's geodesics built before, as the coordinator has them."""
    first_plan_seconds("paper.toml", 1, 0)  # numba's kernels loaded before timing
    timed = []
    for seed in SEEDS:
        world_of(load_scenario(SCENARIOS / config).with_overrides(controller="anicov", agents=agents, seed=seed))
        timed.append(first_plan_seconds(config, agents, seed)[0])
    return timed[0], timed[1:]


def main_maps() -> None:
    """Each case in a process of its own, so that the first team pays the programme as a run does."""
    print(f"machine: {describe_machine()}")
    print("| map | N | first team's first plan, s (programme included) | next teams', s |")
    print("|---|---|---|---|")
    for config, agents in MAP_CASES:
        found = subprocess.run(
            [sys.executable, __file__, "--map-case", config, str(agents)], capture_output=True, text=True, check=True
        )
        print(found.stdout.strip(), flush=True)


def main() -> None:
    if "--map-case" in sys.argv:
        config, agents = sys.argv[-2], int(sys.argv[-1])
        first, next_ = map_first_plans(config, agents)
        print(f"| {config} | {agents} | {first:.2f} | {', '.join(f'{s:.2f}' for s in next_)} |")
        return
    if "--maps" in sys.argv:
        main_maps()
        return
    print(f"machine: {describe_machine()}")
    first_plan_seconds("paper.toml", 1, 0)  # numba's kernels loaded before timing
    for config in sorted({config for config, _ in CASES}):
        print(f"stations' layouts of {config}, once per process: {layout_seconds(config):.2f} s")
    for config in sorted({config for config, _ in CASES}):
        first_plan_seconds(config, 1, 0)  # each scenario's layouts computed again (kept), before timing plans
    print("| scenario | N | first plan, s (seeds 0-2) | orbits |")
    print("|---|---|---|---|")
    for config, agents in CASES:
        timed = [first_plan_seconds(config, agents, seed) for seed in SEEDS]
        seconds = ", ".join(f"{s:.2f}" for s, _ in timed)
        orbits = ", ".join(str(n) for _, n in timed)
        print(f"| {config} | {agents} | {seconds} | {orbits} |")


if __name__ == "__main__":
    main()
