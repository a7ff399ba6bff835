"""The coordinator process: Algorithms 1–2 for the team, membership, snapshots, the end of the run.

It keeps its own replica of the map, gathers every agent's state, runs the
planner (the same :class:`anicov.engine.Planner` as the in-process engine),
and publishes each step's go with the objectives. It tracks who is alive
through liveliness tokens, serves snapshots to late or restarted processes,
detects full coverage, announces the end of the run and writes the run
directory (trajectory.csv, summary.json, plots), as ``anicov run`` does.
"""

from __future__ import annotations

import logging
import math
import os
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import zenoh

from model.coverage_map import load_kernels as load_map_kernels
from model.planning import Planner
from model.run import SNAPSHOT_PERIOD, TRACE_FIELDS, RunResult
from model.scenario import Scenario
from protocol.inbox import Inbox, Membership, Received
from protocol.keys import TeamKeys, agent_of_key
from protocol.messages import AgentState, AgentStep, Limits, MapDelta, Objectives, RunControl, Snapshot, StepGo, encode
from protocol.recovery import GAP_CHECK_PERIOD, History, LossTimer, Relay, fetch, fetch_snapshot, fill_gaps
from protocol.replica import MapReplica
from protocol.session import open_session, team_publisher
from runtime.lifecycle import EXIT_FAILED, EXIT_INCOMPLETE, EXIT_OK, StopFlag, parent_is_gone, settle_garbage_collector
from runtime.rundir import write_counts

log = logging.getLogger("anicov.coordinator")

START_TIMEOUT = 120.0
"""Seconds to wait for every agent's hello before giving up."""
HISTORY_TIMEOUT = 30.0
"""Seconds a restarted coordinator waits for the agents' full histories (a long run has many steps)."""
STATUS_PERIOD = 0.25
"""Seconds between progress messages on run/status."""


@dataclass
class CoordinatorOptions:
    team: str
    clock: str = "lockstep"
    speed: float = 1.0
    out: str | None = None
    drop_rate: float = 0.0
    await_logger: bool = False  # start only once a logger listens (so its recording has every step)


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

    def record(self, state: AgentState) -> None:
        """Keep a state's trace row and, if it is the agent's latest, its pose at the end of the step."""
        if state.step >= 0:
            row = self.rows.get(state.step)
            if row is None:
                row = self.rows[state.step] = np.full((self.agents, len(TRACE_FIELDS)), np.nan)
            row[state.agent] = (*state.pose, state.v, state.omega, state.e_omega)
        if state.step >= self.last_step.get(state.agent, -2):
            self.final_poses[state.agent] = state.next_pose
            self.last_step[state.agent] = state.step


class Coordinator:
    def __init__(self, scenario: Scenario, options: CoordinatorOptions) -> None:
        self.scenario = scenario
        self.options = options
        self.keys = TeamKeys(options.team)
        rows, cols = scenario.grid_shape
        self.limits = Limits(rows, cols, scenario.agents)
        self.replica = MapReplica(rows, cols, scenario.cell, scenario.lambda_star)
        self.planner = Planner(scenario)
        self.inbox = Inbox(self.limits, options.drop_rate, seed=999)
        self.alive: set[int] = set()
        self.members: set[int] = set()
        self.positions: dict[int, tuple[float, float]] = {}
        self.latest_state_step: dict[int, int] = {}
        self.log = RunLog(scenario.agents)
        self.membership_changed = False
        self.targets = np.zeros((0, 2))
        self.bytes_sent = 0
        self.open_step: int | None = 0 if options.clock == "lockstep" else None
        self.held_back: list[MapDelta] = []
        self.open_deltas: dict[int, MapDelta] = {}
        self.states_by_step: dict[int, dict[int, AgentState]] = {}  # lockstep: states not yet sent in a go
        self.closed_states: dict[int, AgentState] = self.states_by_step.get(-1, {})  # the hellos, for go 0
        self.lock = threading.Lock()  # the snapshot queryable reads the replica from Zenoh's thread
        self.relay = Relay(self.keys.coordinator_relay)
        self.joining: dict[int, tuple[float, float]] = {}  # lockstep: returning robots, admitted at the next go

    def snapshot_payload(self) -> bytes:
        """The replica with the last known poses, for a late or restarted process (Zenoh's thread)."""
        with self.lock:
            snapshot = self.replica.snapshot(dict(self.log.final_poses))
        return encode(snapshot)

    def handle(self, item: Received | Membership) -> None:
        with self.lock:
            self._handle(item)

    def _handle(self, item: Received | Membership) -> None:
        if isinstance(item, Membership):
            if item.alive:
                self.alive.add(item.agent)
                if self.members and item.agent not in self.members and self.options.clock == "realtime":
                    # A restarted robot: it resumes from our snapshot; plan for it again.
                    self.members.add(item.agent)
                    self.membership_changed = True
                    self.log.events.append(f"agent {item.agent} rejoined")
                    log.info("agent %d rejoined the team", item.agent)
            else:
                self.alive.discard(item.agent)
                if item.agent in self.members:
                    self.members.discard(item.agent)
                    self.membership_changed = True
                    self.log.events.append(f"agent {item.agent} left")
                    log.warning("agent %d left the team", item.agent)
            return
        message = item.message
        if isinstance(message, AgentStep):
            self._take_delta(message.delta)
            self._take_state(message.state)
            if self.open_step is None and item.payload:  # realtime: kept for when its sender dies
                self.relay.add(message.agent, message.delta.seq, item.payload)
        elif isinstance(message, MapDelta):
            self._take_delta(message)
        elif isinstance(message, AgentState):  # a hello (step −1), or a state from a history
            if message.step < 0 and self.open_step and self.members and message.agent not in self.members:
                # Lockstep, a robot that left comes back (restarted with its id): it joins at the next go.
                self.joining[message.agent] = (message.next_pose[0], message.next_pose[1])
                return
            self._take_state(message)

    def _take_delta(self, delta: MapDelta) -> None:
        if self.open_step is not None and delta.seq > self.open_step:
            self.held_back.append(delta)  # lockstep: Λ must not run ahead of the step being closed
        else:
            self.offer(delta)

    def _take_state(self, state: AgentState) -> None:
        self.log.record(state)
        if self.open_step is not None and state.step >= self.open_step - 1:
            self.states_by_step.setdefault(state.step, {})[state.agent] = state  # for the go of step + 1
        if state.step >= self.latest_state_step.get(state.agent, -2):
            self.latest_state_step[state.agent] = state.step
            self.positions[state.agent] = (state.next_pose[0], state.next_pose[1])

    def open_next_step(self) -> list[MapDelta]:
        """Lockstep: after the open step was closed (Λ_{k+1} measured), let step k+1's deltas in.

        Returns the closed step's deltas, for the go that announces the next step."""
        with self.lock:
            return self._open_next_step()

    def _open_next_step(self) -> list[MapDelta]:
        assert self.open_step is not None
        closed = list(self.open_deltas.values())
        self.closed_states = self.states_by_step.pop(self.open_step, {})
        self.open_deltas = {}
        self.open_step += 1
        for agent, position in self.joining.items():
            # It owes its first delta for the step the next go opens; the steps it missed will never come.
            self.members.add(agent)
            self.positions[agent] = position
            self.replica.skip(agent, self.open_step - 1)
            self.membership_changed = True
            self.log.events.append(f"agent {agent} rejoined at step {self.open_step}")
            log.info("agent %d rejoined the team at step %d", agent, self.open_step)
        self.joining = {}
        waiting = [delta for delta in self.held_back if delta.seq > self.open_step]
        for delta in self.held_back:
            if delta.seq <= self.open_step:
                self.offer(delta)
        self.held_back = waiting
        return closed

    def offer(self, delta: MapDelta) -> None:
        """Apply a delta; in lockstep keep the open step's for the next go."""
        if self.replica.apply(delta) and delta.seq == self.open_step:
            self.open_deltas[delta.agent] = delta

    def plan_if_due(self, step: int) -> Objectives | None:
        """Objectives for a go: on a replanning step or after a change of members, else None."""
        if step % self.scenario.replan_steps == 0 or self.membership_changed:
            return self.plan(step)
        return None

    def go(self, step: int, deltas: list[MapDelta], final: bool = False) -> StepGo:
        """Lockstep: step ``step`` may start, with every member's previous delta and state (the closed
        step's). The final go only completes every replica: no objectives."""
        kept = tuple(sorted((delta for delta in deltas if delta.agent in self.members), key=lambda d: d.agent))
        states = tuple(self.closed_states[agent] for agent in sorted(self.closed_states) if agent in self.members)
        objectives = self.plan_if_due(step) if self.members and not final else None
        return StepGo(step, tuple(sorted(self.members)), kept, objectives, states)

    def plan(self, step: int) -> Objectives:
        members = sorted(self.members)
        positions = np.array([self.positions[agent] for agent in members], dtype=np.float64).reshape(-1, 2)
        if members and (
            step % self.scenario.replan_steps == 0 or self.membership_changed or len(self.targets) != len(members)
        ):
            self.targets = self.planner.plan(self.replica.map.lack_of_coverage(), positions)
            self.membership_changed = False
            labels = self.planner.blobs.labels
            return Objectives(
                step,
                tuple(members),
                self.targets,
                self.planner.blobs.positions,
                None if labels is None else labels.astype(np.uint16),
            )
        return Objectives(step, tuple(members), self.targets, self.planner.blobs.positions)

    def missing(self, step: int) -> list[int]:
        """Members whose delta or state of ``step`` has not arrived."""
        return [
            agent
            for agent in sorted(self.members)
            if not self.replica.has(agent, step) or self.latest_state_step.get(agent, -2) < step
        ]

    def step_complete(self, step: int) -> bool:
        """Lockstep: every member's delta and state of ``step`` are in."""
        return all(
            self.replica.has(agent, step) and self.latest_state_step.get(agent, -2) >= step for agent in self.members
        )

    def rebuild(
        self, messages: list[MapDelta | AgentState], members: set[int], snapshot: Snapshot | None = None
    ) -> int:
        """A restarted coordinator: replay the agents' histories as the lost coordinator lived them.

        Step by step from 0, the deltas of step s−1 enter the replica (Λ_s), e_D
        and the map snapshots are logged, the states of step s are recorded and,
        in lockstep on a replanning step, the planner runs on Λ_s and the poses
        of step s, so its memory of blobs is the one the lost coordinator had.
        Returns the step to resume at: the latest step every member has
        published. In lockstep that step is still open (its deltas go into the
        next go), so a run that lost its coordinator still equals the engine.
        Agents gone before the restart left no history: their coverage is
        adopted from a member's ``snapshot``.
        """
        deltas: dict[int, list[MapDelta]] = {}
        states: dict[int, list[AgentState]] = {}
        for message in messages:
            if isinstance(message, MapDelta) and message.agent in members:
                deltas.setdefault(message.seq, []).append(message)
            elif isinstance(message, AgentState) and message.step >= 0 and message.agent in members:
                states.setdefault(message.step, []).append(message)
        latest: dict[int, int] = {}
        for step, of_step in states.items():
            for state in of_step:
                latest[state.agent] = max(latest.get(state.agent, -1), step)
        if not latest:
            raise RuntimeError(f"the team is running but no history of agents {sorted(members)} could be read")
        resume = min(latest.values())
        snapshot_steps = max(1, round(SNAPSHOT_PERIOD / self.scenario.dt))
        lockstep = self.open_step is not None
        with self.lock:
            self.members = set(latest)
            for step in range(resume + 1):
                if step > 0:
                    for delta in deltas.get(step - 1, []):
                        self.replica.apply(delta)
                    self.log.errors.append(self.replica.map.domain_error())
                if step % snapshot_steps == 0:
                    self.take_snapshot(step * self.scenario.dt)
                for state in states.get(step, []):
                    self.log.record(state)
                    self.positions[state.agent] = (state.pose[0], state.pose[1])
                if lockstep and step % self.scenario.replan_steps == 0:
                    self.plan(step)
                for state in states.get(step, []):
                    self.latest_state_step[state.agent] = step
                    self.positions[state.agent] = (state.next_pose[0], state.next_pose[1])
            gone = set(snapshot.applied) - members if snapshot is not None else set()
            if gone and snapshot is not None:
                self.replica.adopt(snapshot, [m for m in messages if isinstance(m, MapDelta)], gone)
                self.log.events.append(f"coverage of agents {sorted(gone)} taken from a member's snapshot")
            if lockstep:
                self.open_step = resume
            # What lies beyond: the open step's deltas (for the next go) and any later ones.
            for message in messages:
                if isinstance(message, MapDelta) and message.seq >= resume and message.agent in members:
                    self._handle(Received("", message))
                elif isinstance(message, AgentState) and message.step >= resume and message.agent in members:
                    self._handle(Received("", message))
        return resume

    def take_snapshot(self, time_now: float) -> None:
        lack = self.replica.map.lack_of_coverage()
        self.log.snapshot_times.append(time_now)
        self.log.snapshots.append(np.round(lack * 255.0).astype(np.uint8))

    def result(self, steps: int, completed: bool, completion_step: int) -> RunResult:
        n = self.scenario.agents
        trace = np.full((steps + 1, n, len(TRACE_FIELDS)), np.nan)
        for step, row in self.log.rows.items():
            if step < steps:
                trace[step] = row
        for agent, pose in self.log.final_poses.items():
            trace[steps, agent, :3] = pose
            trace[steps, agent, 3:] = 0.0
        errors = np.array(self.log.errors[: steps + 1])
        return RunResult(
            scenario=self.scenario,
            completed=completed,
            completion_time=completion_step * self.scenario.dt if completed else math.inf,
            steps=steps,
            trace=trace,
            errors=errors,
            snapshot_times=self.log.snapshot_times,
            snapshots=self.log.snapshots,
            final_lack=self.replica.map.lack_of_coverage(),
        )


def run_coordinator(scenario: Scenario, options: CoordinatorOptions, config: zenoh.Config, stop: StopFlag) -> int:
    node = Coordinator(scenario, options)
    keys = node.keys
    parent = os.getppid()
    lockstep = options.clock == "lockstep"
    outcome: tuple[int, bool, int] | None = None
    with open_session(config) as session:
        session.declare_subscriber(keys.all_steps, node.inbox.on_sample)
        session.liveliness().declare_subscriber(keys.alive_agents, node.inbox.on_liveliness, history=True)
        session.declare_queryable(keys.snapshot, lambda query: query.reply(keys.snapshot, node.snapshot_payload()))
        objectives_publisher = team_publisher(session, keys.objectives)
        go_publisher = team_publisher(session, keys.go)
        go_history = History(keys.go_history)
        loss = LossTimer()
        session.declare_queryable(keys.go_history, go_history.serve)
        if not lockstep:
            session.declare_queryable(keys.coordinator_relay, node.relay.serve)

        def publish_go(go: StepGo) -> None:
            payload = encode(go)
            go_history.add(go.step, payload)
            publish(go_publisher, payload)

        control_publisher = team_publisher(session, keys.control)
        status_publisher = team_publisher(session, keys.status)
        token = session.liveliness().declare_token(keys.alive("coordinator"))
        settle_garbage_collector()
        load_map_kernels()  # while the agents start, not in step 0

        def publish(publisher: zenoh.Publisher, payload: bytes) -> None:
            node.bytes_sent += len(payload)
            publisher.put(payload)

        # Wait until every agent has said hello (its pose at t_0), unless the team is already running:
        # then this coordinator replaces one that died, and rebuilds from the agents' histories.
        running: list[MapDelta | AgentState] = []
        deadline = time.monotonic() + START_TIMEOUT
        next_look = 0.0
        logger_ready = not options.await_logger
        while (len(node.positions) < scenario.agents or not logger_ready) and not running and not stop.stopped:
            if not logger_ready:
                logger_ready = any(
                    r.ok is not None for r in session.liveliness().get(keys.alive("logger"), timeout=0.5)
                )
            if time.monotonic() >= next_look:  # lockstep agents that lost their coordinator wait in silence
                fetch(session, keys.all_histories, node.inbox, first=0, last=0, timeout=0.5)
                next_look = time.monotonic() + 0.5
            item = node.inbox.get(timeout=0.1)
            if item is not None:
                if is_running(item):
                    running += [item.message.delta, item.message.state]  # type: ignore[union-attr]
                else:
                    node.handle(item)
            if parent_is_gone(parent) or time.monotonic() > deadline:
                break
        step = 0
        if running:
            # Robots that died before this coordinator started left no history, but their coverage is in
            # every live replica: take one, first (anything in it is then also in the histories below).
            # Any live agent's replica will do (dead ones do not answer).
            snapshot = member_snapshot(session, keys, node.limits, set(range(scenario.agents)))
            # Ends when every history has replied in full; live messages keep coming meanwhile,
            # so take only what is queued then: the rest is for the main loop.
            fetch(session, keys.all_histories, node.inbox, first=0, timeout=HISTORY_TIMEOUT)
            for _ in range(node.inbox.queue.qsize()):
                item = node.inbox.get(timeout=0)
                if item is None:
                    break
                if is_running(item):
                    running += [item.message.delta, item.message.state]  # type: ignore[union-attr]
                else:
                    node.handle(item)
            # Members: whoever holds a liveliness token now, and whoever answered from its history
            # (only a live process answers; a token may not have reached this new session yet).
            members = alive_agents(session, keys, scenario.agents) | node.alive
            members |= {message.agent for message in running if isinstance(message, AgentState)}
            step = node.rebuild(running, members, snapshot)
            node.log.events.append(f"coordinator resumed at step {step}")
            log.warning(
                "a running team: resumed at step %d from the histories of agents %s", step, sorted(node.members)
            )
        elif len(node.positions) < scenario.agents or not logger_ready:
            log.error(
                "only %d of %d agents said hello%s; giving up",
                len(node.positions),
                scenario.agents,
                "" if logger_ready else " and no logger appeared",
            )
            publish(control_publisher, encode(RunControl("abort", 0, reason="agents missing at start")))
            token.undeclare()
            return stop.exit_code(EXIT_FAILED)
        else:
            node.members = set(range(scenario.agents))
            log.info("all %d agents present; starting (%s clock)", scenario.agents, options.clock)
            node.take_snapshot(0.0)
        snapshot_steps = max(1, round(SNAPSHOT_PERIOD / scenario.dt))
        last_status = 0.0
        step_resumed = step if running else None
        began = last_news = time.monotonic()
        started = began - step * scenario.dt / options.speed  # realtime: the wall-clock time of step 0
        next_plan = time.monotonic()
        next_gap_check = next_plan + GAP_CHECK_PERIOD
        if lockstep and not running:
            node.closed_states = node.states_by_step.pop(-1, {})  # the hellos: where everyone starts
            publish_go(node.go(0, []))
        elif not lockstep:
            publish(objectives_publisher, encode(node.plan(0)))
        while outcome is None and not stop.stopped:
            if parent_is_gone(parent):
                stop.set()
                break
            if lockstep:
                # Close steps in order as their deltas and states come in; each closed step k−1
                # becomes the go for step k, carrying every member's delta of step k−1.
                item = node.inbox.get(timeout=loss.patience)
                if item is not None:
                    node.handle(item)
                    last_news = time.monotonic()
                elif time.monotonic() - last_news >= loss.patience:
                    loss.recovering()
                    # Something of this step is missing (lost on the way): ask its sender's history.
                    for agent in node.missing(step):
                        fetch(session, keys.agent_history(agent), node.inbox, first=step, last=step)
                    last_news = time.monotonic()
                while outcome is None and node.step_complete(step):
                    # The replica now holds exactly Λ_{k+1}: every delta of steps ≤ k, none later.
                    step += 1
                    loss.step_done()
                    node.log.errors.append(node.replica.map.domain_error())
                    if step % snapshot_steps == 0:
                        node.take_snapshot(step * scenario.dt)
                    if node.replica.map.complete or step >= scenario.max_steps or not node.members:
                        outcome = (step, node.replica.map.complete, step)
                        # The last go only completes every replica; the agents then wait for the end.
                        publish_go(node.go(step, node.open_next_step(), final=True))
                        break
                    publish_go(node.go(step, node.open_next_step()))
            else:
                item = node.inbox.get(timeout=0.01)
                while item is not None:
                    node.handle(item)
                    item = node.inbox.get(timeout=0)
                if time.monotonic() >= next_gap_check:
                    fill_gaps(session, keys, node.replica, node.inbox)
                    next_gap_check = time.monotonic() + GAP_CHECK_PERIOD
                reached = max(node.latest_state_step.values(), default=-1) + 1
                while len(node.log.errors) <= reached:
                    node.log.errors.append(node.replica.map.domain_error())
                    if (len(node.log.errors) - 1) % snapshot_steps == 0:
                        node.take_snapshot((len(node.log.errors) - 1) * scenario.dt)
                if node.replica.map.complete or reached >= scenario.max_steps or not node.members:
                    node.log.errors[reached] = node.replica.map.domain_error()  # the map as it ends
                    outcome = (reached, node.replica.map.complete, reached)
                    break
                now = time.monotonic()
                if now >= next_plan:
                    step = int((now - started) * options.speed / scenario.dt)
                    objectives = node.plan(0)  # as step 0 of a block: replan on every wall-clock period
                    publish(
                        objectives_publisher,
                        encode(
                            Objectives(
                                step, objectives.members, objectives.targets, objectives.blobs, objectives.labels
                            )
                        ),
                    )
                    next_plan = now + scenario.replan_period / options.speed
            now = time.monotonic()
            if now - last_status >= STATUS_PERIOD:
                publish(status_publisher, encode(RunControl("status", step, False, node.replica.map.domain_error())))
                last_status = now
        if outcome is not None:
            steps, completed, completion_step = outcome
            done = encode(RunControl("done", steps, completed, node.replica.map.domain_error()))
            go_history.final = [done]  # an agent that lost the end of the run finds it here
            publish(control_publisher, done)
            log.info(
                "run %s after %d steps (e_D = %.4f)",
                "complete" if completed else "incomplete",
                steps,
                node.replica.map.domain_error(),
            )
        else:
            publish(
                control_publisher,
                encode(RunControl("abort", step, False, node.replica.map.domain_error(), reason="coordinator stopped")),
            )
        # Deltas still in flight (realtime agents step until they hear the end) join the map.
        # (Lockstep: nothing is in flight, the last go closed every step.)
        node.open_step = None
        if not lockstep:
            node.inbox.drain(0.5, node.handle)
        if outcome is not None:
            publish(control_publisher, done)  # again, for whoever lost the first (it is idempotent)
        if not lockstep:  # and those lost on the way, last ones included (see fill_gaps)
            fill_gaps(session, keys, node.replica, node.inbox, to_the_end=range(scenario.agents))
            node.inbox.drain(0.5, node.handle)
        token.undeclare()
        counts = (
            node.inbox.counts()
            | node.replica.counts()
            | {
                "bytes_sent": node.bytes_sent,
                "wall_seconds": time.monotonic() - began,
                "events": node.log.events,
                "resumed_at": step_resumed,
            }
        )
        if outcome is not None and options.out:
            # Still on the bus while writing: a late logger can fetch the final map's snapshot.
            steps, completed, completion_step = outcome
            write_run_directory(node.result(steps, completed, completion_step), Path(options.out), counts)
    if outcome is None:
        return stop.exit_code(EXIT_FAILED)
    return EXIT_OK if outcome[1] else EXIT_INCOMPLETE


def alive_agents(session: zenoh.Session, keys: TeamKeys, agents: int) -> set[int]:
    """The agents whose liveliness token is declared now (asked, not waited for)."""
    alive = set()
    for reply in session.liveliness().get(keys.alive_agents, timeout=2.0):
        if reply.ok is not None:
            agent = agent_of_key(str(reply.ok.key_expr))
            if agent is not None and 0 <= agent < agents:
                alive.add(agent)
    return alive


def member_snapshot(session: zenoh.Session, keys: TeamKeys, limits: Limits, members: set[int]) -> Snapshot | None:
    """The replica of the first member that answers, or None."""
    for agent in sorted(members):
        snapshot = fetch_snapshot(session, keys.agent_snapshot(agent), limits, timeout=2.0)
        if snapshot is not None:
            return snapshot
    return None


def is_running(item: Received | Membership) -> bool:
    """A step already taken: the team is past its hellos."""
    return isinstance(item, Received) and isinstance(item.message, AgentStep)


def write_run_directory(result: RunResult, out_dir: Path, counts: dict[str, object]) -> None:
    """trajectory.csv, summary.json and plots, exactly as ``anicov run`` writes them."""
    from runtime.plots import write_run_plots
    from runtime.rundir import summary_of, write_summary, write_trajectory

    out_dir.mkdir(parents=True, exist_ok=True)
    write_trajectory(result, out_dir / "trajectory.csv")
    write_summary(summary_of(result), out_dir / "summary.json")
    write_counts(out_dir / "coordinator_counts.json", counts)
    write_run_plots(result, out_dir)
