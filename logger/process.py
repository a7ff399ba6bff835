"""The logger process: subscribes to the whole team and writes its rerun recording.

It keeps its own replica of the map (so a late start still ends with the full
map: it loads the coordinator's snapshot first), logs every agent's state,
the objectives and blobs, e_D, and the team's events, and flushes the
recording when the run ends or when it is stopped.
"""

from __future__ import annotations

import logging
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import zenoh

from logger.recording import RunRecorder
from model.scenario import Scenario
from protocol.inbox import Inbox, Membership, Received
from protocol.keys import TeamKeys
from protocol.messages import AgentState, AgentStep, Limits, Objectives, RunControl, StepGo
from protocol.recovery import fetch, fetch_snapshot
from protocol.replica import MapReplica
from protocol.session import open_session
from runtime.lifecycle import EXIT_OK, StopFlag, parent_is_gone, settle_garbage_collector
from runtime.rundir import write_counts

log = logging.getLogger("logger.process")

FLUSH_PERIOD = 0.5
"""Seconds between sends of the buffered per-step columns."""
READ_PERIOD = 0.25
"""Lockstep: seconds between reads of the coordinator's history of gos (the live view lags this much)."""


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


class TeamLogger:
    def __init__(self, scenario: Scenario, options: LoggerOptions) -> None:
        self.scenario = scenario
        rows, cols = scenario.grid_shape
        self.limits = Limits(rows, cols, scenario.agents)
        self.replica = MapReplica(rows, cols, scenario.cell, scenario.lambda_star)
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

    def handle(self, item: Received | Membership) -> None:
        if isinstance(item, Membership):
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
        elif isinstance(message, StepGo):  # lockstep: the whole previous step in one message
            if message.step < self.next_go:
                return  # read twice (a batch overlapped the previous one)
            self.next_go = message.step + 1
            for delta in message.deltas:
                self.replica.apply(delta)
            for state in message.states:
                self.take_state(state)
            if message.objectives is not None:
                objectives = message.objectives
                self.recorder.objectives(
                    objectives.step,
                    self.positions,
                    objectives.members,
                    objectives.targets,
                    objectives.blobs,
                    objectives.labels,
                )
        elif isinstance(message, Objectives):
            self.recorder.objectives(
                message.step, self.positions, message.members, message.targets, message.blobs, message.labels
            )
        elif isinstance(message, RunControl) and message.kind in ("done", "abort"):
            self.finished = message

    def take_state(self, state: AgentState) -> None:
        """A state of step k; once the first of step k arrives (after its deltas), e_D and the map of k+1."""
        if state.step >= 0:
            self.recorder.state(state.agent, state.step, *state.pose, state.v, state.omega, state.e_omega)
        self.positions[state.agent] = state.next_pose[:2]
        if state.step + 1 > self.latest_step:
            self.latest_step = state.step + 1
            self.recorder.domain_error(self.latest_step, self.replica.map.domain_error())
            if self.latest_step % self.recorder.map_every == 0:
                self.recorder.lack_map(self.latest_step, self.replica.map.lack_of_coverage())

    def load_snapshot(self, session: zenoh.Session, keys: TeamKeys) -> None:
        """A late logger starts from the coordinator's map."""
        snapshot = fetch_snapshot(session, keys.snapshot, self.limits, timeout=5.0)
        if snapshot is None:
            return
        self.replica.load(snapshot)
        if snapshot.applied:  # a late start: the gos before the snapshot's map are already in it
            self.next_go = max(self.next_go, min(seq for seq, _ in snapshot.applied.values()) + 2)
        log.info("loaded the coordinator's snapshot (e_D = %.4f)", self.replica.map.domain_error())

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
        self.recorder.close()


def run_logger(scenario: Scenario, options: LoggerOptions, config: zenoh.Config, stop: StopFlag) -> int:
    node = TeamLogger(scenario, options)
    keys = TeamKeys(options.team)
    parent = os.getppid()
    with open_session(config) as session:
        # Lockstep bundles every step's deltas, states and objectives in the coordinator's go. The
        # logger reads them in batches from the coordinator's history rather than one sample a step:
        # a process's cost is per message, not per byte, and this one is off the critical path.
        lockstep = options.clock == "lockstep"
        traffic = () if lockstep else (keys.all_steps, keys.objectives)
        for key in (*traffic, keys.control):
            session.declare_subscriber(key, node.inbox.on_sample)
        session.liveliness().declare_subscriber(keys.alive_agents, node.inbox.on_liveliness, history=True)
        token = session.liveliness().declare_token(keys.alive("logger"))
        settle_garbage_collector()
        node.load_snapshot(session, keys)
        next_flush = time.monotonic() + FLUSH_PERIOD
        next_read = 0.0

        def read_gos() -> None:
            """Every go since the last read (and the end of the run, once known), in step order."""
            fetch(session, keys.go_history, node.inbox, first=node.next_go, timeout=5.0, recovery=False)

        while node.finished is None and not stop.stopped and not parent_is_gone(parent):
            if lockstep and time.monotonic() >= next_read:
                read_gos()
                next_read = time.monotonic() + READ_PERIOD
            item = node.inbox.get(timeout=READ_PERIOD / 2)
            if item is not None:
                node.handle(item)
            if time.monotonic() >= next_flush:
                node.recorder.flush_states()
                next_flush = time.monotonic() + FLUSH_PERIOD
        # Drain what is already here (the last deltas travel beside the end-of-run message).
        if lockstep and node.finished is not None:
            read_gos()  # the gos up to the end, if the end came first on run/control
        deadline = time.monotonic() + 0.5
        while time.monotonic() < deadline and (item := node.inbox.get(timeout=0.05)) is not None:
            node.handle(item)
        if node.finished is not None and not node.replica.map.complete:
            node.load_snapshot(session, keys)  # anything lost on the way: the coordinator's map is the reference
        token.undeclare()
    node.finish()
    write_counts(Path(options.counts_file) if options.counts_file else None, node.inbox.counts())
    return stop.exit_code(EXIT_OK)
