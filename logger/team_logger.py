"""What the logger makes of the team's messages: its map replica, and the recording each message becomes.

No Zenoh session here: :class:`TeamLogger` is fed the inbox's items (and the
coordinator's snapshot, once fetched) by the process shell (logger/process.py),
or by a test.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from logger.recording import RunRecorder
from model.scenario import Scenario
from protocol.inbox import Inbox, Membership, Received
from protocol.messages import AgentState, AgentStep, Limits, Objectives, RunControl, Snapshot, StepGo, Traffic
from protocol.replica import MapReplica


@dataclass
class LoggerOptions:
    team: str
    recording_id: str
    path: str | None
    spawn_viewer: bool = False
    serve_web: bool = False
    map_every: int = 50
    counts_file: str | None = None
    clock: str = "lockstep"
    web_port: int = 9090
    grpc_port: int = 9876
    no_coordinator: bool = False  # a team without one: agree with the agents, end when they have all left


class TeamLogger:
    def __init__(self, scenario: Scenario, options: LoggerOptions) -> None:
        self.scenario = scenario
        self.options = options
        self.limits = Limits.of(scenario)
        self.replica = MapReplica.of(scenario)
        self.inbox = Inbox(self.limits, defer_decoding=True)
        self.recorder = RunRecorder(
            scenario,
            options.recording_id,
            Path(options.path) if options.path else None,
            options.spawn_viewer,
            options.serve_web,
            options.map_every,
            options.web_port,
            options.grpc_port,
        )
        self.positions = np.full((scenario.agents, 2), np.nan)
        self.latest_step = -1
        self.logged_map_step = -1
        self.finished: RunControl | None = None
        self.next_go = 0  # lockstep: the first go not read yet
        self.traffic: dict[str, Traffic] = {}  # each process's latest report
        self.joined: set[int] = set()  # agents whose liveliness token was seen
        self.alive: set[int] = set()
        self.started = time.monotonic()  # the logger's own traffic: what its inbox took in since

    def handle(self, item: Received | Membership) -> None:
        if isinstance(item, Membership):
            if item.alive:
                self.joined.add(item.agent)
                self.alive.add(item.agent)
            else:
                self.alive.discard(item.agent)
            self.recorder.event(
                max(self.latest_step, 0),
                f"agent {item.agent} {'joined' if item.alive else 'left'}",
                "INFO" if item.alive else "WARN",
            )
            return
        message = item.message
        if isinstance(message, AgentStep):  # realtime
            self.replica.apply(message.delta)
            self.take_state(message.state)
        elif isinstance(message, AgentState):  # a hello
            self.take_state(message)
        elif isinstance(message, StepGo):
            self.take_go(message)
        elif isinstance(message, Objectives):
            self.take_objectives(message)
        elif isinstance(message, RunControl) and message.kind in ("done", "abort"):
            self.finished = message
        elif isinstance(message, Traffic):
            self.take_traffic(message)

    def take_traffic(self, report: Traffic) -> None:
        """Bytes per second since the process's previous report (none before its first; a restarted
        process, whose counters start again, is taken from its new first report)."""
        process = f"{report.role}-{report.ident}"
        previous = self.traffic.get(process)
        self.traffic[process] = report
        if previous is None or report.seconds <= previous.seconds or report.bytes_out < previous.bytes_out:
            return
        elapsed = report.seconds - previous.seconds
        self.recorder.traffic(
            max(self.latest_step, 0),
            process,
            (report.bytes_in - previous.bytes_in) / elapsed,
            (report.bytes_out - previous.bytes_out) / elapsed,
        )

    def bandwidth(self) -> dict[str, dict[str, float]]:
        """Each process's last report, and the logger's own counters: wall seconds, bytes out and in, and
        their rates."""
        table = {}
        own = Traffic("logger", 0, time.monotonic() - self.started, 0, self.inbox.bytes_received)
        for process, report in sorted((self.traffic | {"logger-0": own}).items()):
            per = 1.0 / report.seconds if report.seconds > 0 else 0.0
            table[process] = {
                "seconds": round(report.seconds, 3),
                "bytes_out": report.bytes_out,
                "bytes_in": report.bytes_in,
                "bytes_out_per_second": round(report.bytes_out * per, 1),
                "bytes_in_per_second": round(report.bytes_in * per, 1),
            }
        return table

    def everyone_left(self) -> bool:
        """Every agent of the team was seen and is gone (a team with no coordinator has ended)."""
        return len(self.joined) == self.scenario.agents and not self.alive

    def take_go(self, go: StepGo) -> None:
        """Lockstep: the whole previous step in one message."""
        if go.step < self.next_go:
            return  # read twice (a batch overlapped the previous one)
        self.next_go = go.step + 1
        for delta in go.deltas:
            self.replica.apply(delta)
        for state in go.states:
            self.take_state(state)
        if go.objectives is not None:
            self.take_objectives(go.objectives)

    def take_objectives(self, objectives: Objectives) -> None:
        self.recorder.objectives(
            objectives.step,
            self.positions,
            objectives.members,
            objectives.targets,
            objectives.blobs,
            objectives.labels,
        )

    def take_state(self, state: AgentState) -> None:
        """A state of step k; once the first of step k arrives (after its deltas), e_D and the map of k+1."""
        if state.step >= 0:
            self.recorder.state(
                state.agent, state.step, *state.pose, state.v, state.omega, state.e_omega, safety=state.safety
            )
        self.positions[state.agent] = state.next_pose[:2]
        if state.step + 1 > self.latest_step:
            self.latest_step = state.step + 1
            self.recorder.domain_error(self.latest_step, self.replica.map.domain_error())
            if self.latest_step % self.recorder.map_every == 0:
                self.recorder.lack_map(self.latest_step, self.replica.map.lack_of_coverage())

    def load_snapshot(self, snapshot: Snapshot) -> None:
        """A late logger starts from the coordinator's map (fetched by the process)."""
        self.replica.load(snapshot)
        if snapshot.applied:  # a late start: the gos before the snapshot's map are already in it
            self.next_go = max(self.next_go, min(seq for seq, _ in snapshot.applied.values()) + 2)

    def finish(self) -> None:
        """The run's final map and its end, then flush everything to the sinks."""
        final_step = self.finished.step if self.finished is not None else max(self.latest_step, 0)
        self.recorder.lack_map(final_step, self.replica.map.lack_of_coverage())
        self.recorder.domain_error(final_step, self.replica.map.domain_error())
        if self.finished is not None:
            text = "run complete" if self.finished.completed else f"run ended: {self.finished.reason or 'incomplete'}"
        else:
            text = "logger stopped before the end of the run"
        self.recorder.event(final_step, text)
        if self.traffic:
            self.recorder.bandwidth_table(final_step, self.bandwidth())
        self.recorder.close()
