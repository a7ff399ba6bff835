"""What both in-process engines (:mod:`anicov.engine`, :mod:`anicov.radio_engine`) need around their
steps: the objectives' distance fields, and the :class:`RunResult` made of the chunks of a run."""

from __future__ import annotations

import math

import numpy as np

from model.paper.coverage_map import CoverageMap
from model.run import TRACE_FIELDS, RunResult
from model.scenario import Scenario
from model.world.world import World


def objective_fields(world: World, objectives: np.ndarray) -> np.ndarray:
    """(N, rows, cols): the distance field of each agent's objective; a placeholder where no wall is."""
    if not world.ground.walls:
        return np.zeros((len(objectives), 1, 1))
    return np.stack([world.field(*target) for target in objectives])


def finish_run(
    scenario: Scenario,
    coverage_map: CoverageMap,
    poses: np.ndarray,
    traces: list[np.ndarray],
    errors: list[np.ndarray],
    steps_done: int,
    snapshot_times: list[float],
    snapshots: list[np.ndarray],
    record_trace: bool,
    plan_time: float | None = None,
    completion_step: int | None = None,
) -> RunResult:
    final_rows = np.zeros((1, scenario.agents, len(TRACE_FIELDS)))
    final_rows[0, :, :3] = poses
    if record_trace:
        trace = np.concatenate([*traces, final_rows]) if traces else final_rows
    else:
        # Without a trace keep only |v| sums, laid out so path_lengths still works.
        speed_sums = np.zeros((2, scenario.agents, len(TRACE_FIELDS)))
        for chunk in traces:
            speed_sums[0, :, 3] += chunk[0, :, 0]
        speed_sums[1] = final_rows[0]
        trace = speed_sums
    completed = coverage_map.complete
    completion_step = steps_done if completion_step is None else completion_step
    return RunResult(
        scenario=scenario,
        completed=completed,
        completion_time=completion_step * scenario.dt if completed else math.inf,
        steps=steps_done,
        trace=trace,
        errors=np.concatenate(errors),
        snapshot_times=snapshot_times,
        snapshots=snapshots,
        final_lack=coverage_map.lack_of_coverage(),
        plan_time=plan_time,
    )
