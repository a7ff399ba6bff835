"""What the coordinator saw of a run: trace rows, e_D(t), snapshots, final poses, events; and the
RunResult built from them, so a team over the bus writes the same run directory as the engine."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from model.run import TRACE_FIELDS, RunResult, quantised_lack
from model.scenario import Scenario
from protocol.messages import AgentState


@dataclass
class RunLog:
    """What the coordinator saw of the run, enough to write the same outputs as the engine."""

    agents: int
    rows: dict[int, np.ndarray] = field(default_factory=dict)  # step → (N, 6), NaN where unseen
    errors: list[float] = field(default_factory=lambda: [1.0])
    final_poses: dict[int, tuple[float, float, float]] = field(default_factory=dict)
    snapshot_times: list[float] = field(default_factory=list)
    snapshots: list[np.ndarray] = field(default_factory=list)
    events: list[str] = field(default_factory=list)
    last_step: dict[int, int] = field(default_factory=dict)
    safety: dict[int, np.ndarray] = field(default_factory=dict)  # step → (N,) safety filter flags
    timed: dict[int, dict[int, tuple[float, float, float]]] = field(
        default_factory=dict
    )  # agent → step → (stamp, x, y)

    def record(self, state: AgentState) -> None:
        """Keep a state's trace row and, if it is the agent's latest, its pose at the end of the step."""
        if state.step >= 0:
            row = self.rows.get(state.step)
            if row is None:
                row = self.rows[state.step] = np.full((self.agents, len(TRACE_FIELDS)), np.nan)
            row[state.agent] = (*state.pose, state.v, state.omega, state.e_omega)
            if state.safety:
                self.safety.setdefault(state.step, np.zeros(self.agents, dtype=np.uint8))[state.agent] = state.safety
            if state.stamp:
                self.timed.setdefault(state.agent, {})[state.step] = (state.stamp, *state.next_pose[:2])
        if state.step >= self.last_step.get(state.agent, -2):
            self.final_poses[state.agent] = state.next_pose
            self.last_step[state.agent] = state.step

    def _end_row(self, trace: np.ndarray, steps: int, agent: int, pose: tuple[float, float, float]) -> None:
        """An agent's last row: where its last step heard took it, at that step's end, so the row follows
        from the one before by eq. 1. In lockstep every agent's last step is ``steps`` − 1 and the row is
        ``steps``, as the engine's. Realtime, an agent a step or two behind the coordinator's count ends
        earlier (it may have stepped on, unheard); one ahead of it ends at ``steps`` with the pose its
        state of that step started from. An agent heard only saying hello has no row."""
        last = self.last_step[agent]
        if last < 0:
            return  # only its hello was heard: it never stepped, it has no trajectory
        if last + 1 <= steps:
            trace[last + 1, agent, :3] = pose
        else:
            trace[steps, agent, :3] = self.rows[steps][agent, :3] if steps in self.rows else np.nan
        trace[min(last + 1, steps), agent, 3:] = 0.0

    def take_snapshot(self, time_now: float, lack: np.ndarray) -> None:
        self.snapshot_times.append(time_now)
        self.snapshots.append(quantised_lack(lack))

    def result(
        self, scenario: Scenario, steps: int, completed: bool, completion_step: int, final_lack: np.ndarray
    ) -> RunResult:
        """A RunResult like the engine's: NaN rows where a realtime state was never heard."""
        trace = np.full((steps + 1, self.agents, len(TRACE_FIELDS)), np.nan)
        for step, row in self.rows.items():
            if step < steps:
                trace[step] = row
        for agent, pose in self.final_poses.items():
            self._end_row(trace, steps, agent, pose)
        flags = np.zeros((steps, self.agents), dtype=np.uint8)
        for step, row in self.safety.items():
            if step < steps:
                flags[step] = row
        return RunResult(
            scenario=scenario,
            completed=completed,
            completion_time=completion_step * scenario.dt if completed else math.inf,
            steps=steps,
            trace=trace,
            errors=np.array(self.errors[: steps + 1]),
            snapshot_times=self.snapshot_times,
            snapshots=self.snapshots,
            final_lack=final_lack,
            safety_flags=flags,
            timed_positions={
                agent: np.array([rows[step] for step in sorted(rows)]) for agent, rows in self.timed.items()
            }
            or None,
        )
