"""A controller written in Python against the compiled ones: whole runs in the engine, agent-steps per second.

The paper's law as a plug-in (examples/paper_in_python.py: the same functions of model.paper.control, called from Python through
model.controllers.plugin_step.decide_with) against the compiled paper controller, on the same scenario and
seed, so the two runs are the same steps (the test suite checks they are equal byte for byte); and the
worked example of examples/ beside them. Each rate is the best of REPEATS whole runs.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from anicov.engine import run_scenario
from bench.machine import describe_machine
from model.scenario import validate

ROOT = Path(__file__).resolve().parent.parent
REPEATS = 3


def rate(controller: str, agents: int) -> tuple[float, int]:
    """(agent-steps/s over a whole run, best of REPEATS; the run's steps) on a 50 × 50 square, seed 1."""
    scenario = validate({"domain": [50.0, 50.0], "agents": agents, "seed": 1, "controller": controller})
    run_scenario(scenario, record_trace=False)  # numba's kernels loaded, the planner's caches warm
    best, steps = 0.0, 0
    for _ in range(REPEATS):
        started = time.perf_counter()
        result = run_scenario(scenario, record_trace=False)
        best, steps = max(best, result.steps * agents / (time.perf_counter() - started)), result.steps
    return best, steps


def main() -> None:
    print(describe_machine())
    print("\n| controller | N | steps | agent-steps/s |\n|---|---|---|---|")
    example = f"{ROOT / 'examples' / 'nearest_uncovered.py'}:NearestUncovered"
    for agents in (1, 4):
        for name, controller in (
            ("paper (compiled)", "paper"),
            ("paper as a Python plug-in", f"{ROOT / 'examples' / 'paper_in_python.py'}:PaperInPython"),
            ("examples/nearest_uncovered.py", example),
        ):
            figure, steps = rate(controller, agents)
            print(f"| {name} | {agents} | {steps} | {figure:,.0f} |", flush=True)


if __name__ == "__main__":
    main()
