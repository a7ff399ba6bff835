"""What the in-process engines (:mod:`anicov.engine`, :mod:`anicov.radio_engine`, :mod:`anicov.physics_engine`)
need around their steps: the objectives' distance fields, the map's snapshots, and the :class:`RunResult`
made of the chunks of a run."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from model.paper.coverage_map import CoverageMap
from model.run import SNAPSHOT_PERIOD, TRACE_FIELDS, RunResult, quantised_lack
from model.scenario import Scenario
from model.world.world import World


def objective_fields(world: World, objectives: np.ndarray) -> np.ndarray:
    """(N, rows, cols): the distance field of each agent's objective; a placeholder where no wall is."""
    if not world.ground.walls:
        return np.zeros((len(objectives), 1, 1))
    return np.stack([world.field(*target) for target in objectives])


@dataclass
class Snapshots:
    """Υ every SNAPSHOT_PERIOD time units and at completion, from Υ at t_0: what the recording and the plots
    show of the map's progress."""

    times: list[float] = field(default_factory=list)
    lacks: list[np.ndarray] = field(default_factory=list)
    next_at: float = SNAPSHOT_PERIOD

    @classmethod
    def start(cls, coverage_map: CoverageMap) -> Snapshots:
        return cls([0.0], [quantised_lack(coverage_map.lack_of_coverage())])

    def take_if_due(self, now: float, coverage_map: CoverageMap) -> bool:
        """A snapshot at ``now`` if one is due (or the map is complete); whether one was taken."""
        if now < self.next_at - 1e-9 and not coverage_map.complete:
            return False
        self.times.append(now)
        self.lacks.append(quantised_lack(coverage_map.lack_of_coverage()))
        self.next_at += SNAPSHOT_PERIOD
        return True


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
