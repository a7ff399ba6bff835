"""What a run produces, as data: the per-step trace, e_D(t), the map snapshots and the plans.

The in-process engine and the coordinator process both build a :class:`RunResult`; the run
directory's writers (``runtime.rundir``, ``runtime.plots``) and the recording read it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from model.planning import Plan
from model.scenario import Scenario
from model.watchdog import Stall

TRACE_FIELDS = ("x", "y", "theta", "v", "omega", "e_omega")
"""Columns of the per-step trace: pose at the start of the step, then what was applied during it."""

SNAPSHOT_PERIOD = 5.0
"""Time between stored lack-of-coverage snapshots (for Fig. 6 and the recording)."""

ProgressCallback = Callable[[float, float], None]
"""Called as progress(sim_time, e_D) after each block of steps."""


def snapshot_steps(dt: float) -> int:
    """Steps between two map snapshots (SNAPSHOT_PERIOD / dt, at least one)."""
    return max(1, round(SNAPSHOT_PERIOD / dt))


def quantised_lack(lack: np.ndarray) -> np.ndarray:
    """Υ (eq. 4) as a snapshot keeps it: uint8, 0 = covered, 255 = untouched."""
    return np.round(lack * 255.0).astype(np.uint8)


@dataclass
class RunResult:
    """Everything a run produced. ``trace`` has one row per step plus the final poses (v = ω = 0)."""

    scenario: Scenario
    completed: bool
    completion_time: float
    steps: int
    trace: np.ndarray  # (steps + 1, N, 6), TRACE_FIELDS
    errors: np.ndarray  # (steps + 1,), e_D at t_0 .. t_steps
    snapshot_times: list[float]
    snapshots: list[np.ndarray]  # Υ as uint8 (0 = covered, 255 = untouched)
    final_lack: np.ndarray
    plan_time: float | None = None  # zig-zag only: when the last lane was finished
    plans: list[Plan] = field(default_factory=list)  # every replan, for the recording
    safety_flags: np.ndarray | None = None  # (steps, N) uint8: what the safety filter did (model.safety.safety)
    radio: dict[str, float] | None = None  # a team on a limited radio (anicov.radio_engine.RadioTeam.figures)
    physics: dict[str, float | int] | None = None  # physics = "mujoco": contacts, true coverage (anicov.physics_engine)
    true_poses: np.ndarray | None = None  # physics = "mujoco": (steps + 1, N, 3) the true poses, beside the trace's
    stalls: list[Stall] = field(default_factory=list)  # the progress watchdog's interventions (model.watchdog)
    given_up: np.ndarray | None = None  # bool (rows, cols): cells the watchdog gave up
    timed_positions: dict[int, np.ndarray] | None = None  # realtime: agent → (M, 3) wall time, x, y after each step

    @property
    def path_lengths(self) -> np.ndarray:
        """Σ |v| dt per agent (steps whose state was never heard, NaN in a realtime trace, count as 0)."""
        return np.nansum(np.abs(self.trace[:-1, :, 3]), axis=0) * self.scenario.dt
