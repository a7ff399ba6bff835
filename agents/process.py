"""The agent process: one robot of the team, on the bus.

It keeps its own replica of the coverage map, decides (v, ω) with the same
functions as the in-process engine (:mod:`model.step`), commands its robot,
and publishes its step (coverage delta and state, one message) every step.
It applies its teammates' deltas and follows the coordinator's objectives.

Clocks:

- ``lockstep``: step k starts when the coordinator's go for step k arrives.
  The go carries every member's step k−1 delta (and, on a replanning step,
  the new objectives), so the replica then holds exactly the engine's Λ_k:
  every agent sees full coverage at the same step, and the run equals the
  in-process engine bit for bit. One message in and one out per agent-step.
- ``realtime``: one step every dt/speed seconds of wall-clock time, with
  whatever has arrived by then; never waits for anyone. Lost deltas are
  fetched from the sender's history (gaps, and at the end of the run).
"""

from __future__ import annotations

import logging
import os
import time
from dataclasses import dataclass
from pathlib import Path

import zenoh

from agents.robot import Robot, SimulatedUnicycle
from model.coverage_map import load_kernels as load_map_kernels
from model.parameters import initial_poses, law_parameters
from model.scenario import Scenario
from model.step import LawParameters, decide_and_sense, load_kernels
from protocol.inbox import Inbox, Membership, Received
from protocol.keys import TeamKeys
from protocol.messages import AgentState, AgentStep, Limits, MapDelta, Objectives, RunControl, StepGo, encode
from protocol.recovery import GAP_CHECK_PERIOD, History, LossTimer, Relay, fetch, fetch_snapshot, fill_gaps
from protocol.replica import MapReplica
from protocol.session import open_session, team_publisher
from runtime.lifecycle import EXIT_FAILED, EXIT_OK, StopFlag, parent_is_gone, settle_garbage_collector
from runtime.rundir import write_counts

log = logging.getLogger("anicov.agent")

END_ONLY = 2**60
"""A history query from this step returns no step, only the end of the run once it is known."""
HELLO_PERIOD = 0.2
"""Seconds between repeated hellos until the coordinator's first go arrives."""


@dataclass
class AgentOptions:
    team: str
    agent: int
    clock: str = "lockstep"
    speed: float = 1.0
    drop_rate: float = 0.0
    counts_file: str | None = None


class AgentNode:
    """The state of one agent process between messages."""

    def __init__(self, scenario: Scenario, options: AgentOptions, robot: Robot | None = None) -> None:
        self.scenario = scenario
        self.options = options
        self.keys = TeamKeys(options.team)
        rows, cols = scenario.grid_shape
        self.limits = Limits(rows, cols, scenario.agents)
        self.replica = MapReplica(rows, cols, scenario.cell, scenario.lambda_star)
        self.law: LawParameters = law_parameters(scenario, self.replica.map)
        self.robot = robot or SimulatedUnicycle(tuple(initial_poses(scenario)[options.agent]), self.law)
        self.inbox = Inbox(self.limits, options.drop_rate, seed=1000 + options.agent)
        self.step = 0
        self.objective: tuple[float, float] | None = None
        self.started = False  # the coordinator has sent the first go or objectives
        self.gos: dict[int, StepGo] = {}  # lockstep: gos received for steps not yet taken
        self.last_go = -1  # lockstep: the step of the last go applied
        self.members_seen: set[int] = set()  # lockstep: the members of the last go applied
        self.rejoining = False  # lockstep: restarted, waiting for a go that lists this agent again
        self.finished: RunControl | None = None
        self.bytes_sent = 0
        self.relay = Relay(self.keys.agent_relay(options.agent))  # realtime: teammates' steps, for when one dies
        self.teammates: set[int] = set()  # alive, by their liveliness tokens
        self.teammates_left: list[int] = []

    # ------------------------------------------------------------ messages

    def handle(self, item: Received | Membership) -> None:
        if isinstance(item, Membership):
            self.note_teammate(item)
            return
        message = item.message
        if isinstance(message, AgentStep):  # realtime: teammates' deltas, applied as they come
            if message.agent != self.options.agent:
                self.replica.apply(message.delta)
                self.relay.add(message.agent, message.delta.seq, item.payload)
        elif isinstance(message, StepGo):
            if message.step >= self.step:
                self.gos[message.step] = message
            self.started = True
        elif isinstance(message, Objectives):
            self.take_targets(message)
            self.started = True
        elif isinstance(message, RunControl) and message.kind in ("done", "abort"):
            self.finished = message

    def note_teammate(self, change: Membership) -> None:
        """A teammate's liveliness token came or went. The coordinator replans for the team; a robot
        logs it (a dead teammate's lost deltas then come from the relays, see protocol.bus.fill_gaps)."""
        if change.agent == self.options.agent:
            return
        if change.alive:
            if change.agent in self.teammates_left:
                log.info("agent %d: teammate %d is back", self.options.agent, change.agent)
            self.teammates.add(change.agent)
        elif change.agent in self.teammates:
            self.teammates.discard(change.agent)
            if self.finished is not None:
                return  # the run is over: teammates leave as they finish
            self.teammates_left.append(change.agent)
            log.warning("agent %d: teammate %d left (its liveliness token is gone)", self.options.agent, change.agent)

    def apply_remaining_gos(self) -> None:
        """At the end of a run: the last go completes the map even if the end arrived first."""
        for step in sorted(self.gos):
            for delta in self.gos.pop(step).deltas:
                if delta.agent != self.options.agent:
                    self.replica.apply(delta)

    def take_targets(self, objectives: Objectives) -> None:
        target = objectives.target_of(self.options.agent)
        if target is not None:
            self.objective = target

    def ready_for_step(self) -> bool:
        """Lockstep: the go for this step is here. Its deltas (every member's previous step) enter
        the replica, which then holds exactly Λ_k, and its objectives, if any, are taken."""
        go = self.gos.pop(self.step, None)
        if go is None:
            return False
        self.last_go = go.step
        if self.members_seen:
            for returning in set(go.members) - self.members_seen:
                self.replica.skip(returning, go.step - 1)  # the steps it was away will never come
        self.members_seen = set(go.members)
        for delta in go.deltas:
            if delta.agent != self.options.agent:
                self.replica.apply(delta)
        if go.objectives is not None:
            self.take_targets(go.objectives)
        if self.replica.map.complete or self.step >= self.scenario.max_steps:
            return False  # the last go only completes the map: wait for the end of the run
        if self.objective is None:
            raise RuntimeError(f"agent {self.options.agent} has no objective at step {self.step}")
        return True

    def admitted(self) -> bool:
        """The team has taken this agent in: any go (or objectives) at the start; after a restart in
        lockstep, a go that lists it again (the coordinator admits a returning robot at a step boundary)."""
        if not self.rejoining:
            return self.started
        listed = [step for step, go in self.gos.items() if self.options.agent in go.members]
        if listed:
            self.join_at(min(listed))
        return not self.rejoining

    def join_at(self, step: int) -> None:
        """A returning robot's first go. The gos before it only complete the map (each delta once, over
        the snapshot); the steps it missed will never come."""
        for earlier in sorted(s for s in self.gos if s < step):
            for delta in self.gos.pop(earlier).deltas:
                if delta.agent != self.options.agent:
                    self.replica.apply(delta)
        self.replica.skip(self.options.agent, step - 1)
        self.members_seen = set(self.gos[step].members)
        self.step = step
        self.rejoining = False

    def waiting_for(self) -> str:
        """What a lockstep step is waiting on, for the log."""
        return f"the coordinator's go for step {self.step}"

    # ------------------------------------------------------------ control

    def control_step(self) -> tuple[MapDelta, AgentState]:
        """Decide, sense and move for the current step (eq. 1–16); return what to publish."""
        assert self.objective is not None
        pose = self.robot.pose()
        v, omega, e_omega, row0, col0, ticks = decide_and_sense(
            self.replica.map.coverage, *pose, self.objective[0], self.objective[1], self.law
        )
        delta = MapDelta(self.options.agent, self.step, row0, col0, ticks)
        self.replica.apply(delta)
        next_pose = self.robot.command(v, omega)
        state = AgentState(self.options.agent, self.step, pose, v, omega, e_omega, next_pose)
        self.step += 1
        return delta, state

    def load_kernels(self) -> None:
        """numba's kernels loaded while the team gathers (see model.step.load_kernels)."""
        load_kernels(self.replica.map.coverage, self.robot.pose(), self.law)
        load_map_kernels()

    def hello(self) -> AgentState:
        pose = self.robot.pose()
        return AgentState(self.options.agent, -1, pose, 0.0, 0.0, 0.0, pose)

    def resume_from_snapshot(self, session: zenoh.Session) -> bool:
        """A restarted robot: if the coordinator's snapshot knows this agent, resume where it stopped.

        The map and the applied sequences come from the snapshot (deltas arriving
        meanwhile are applied once). The last steps before the crash may have
        reached teammates but not the coordinator: they come back from the
        relays, so that no sequence is ever used for two different deltas. The
        step continues after this agent's last delta anyone holds, and the
        simulated robot restarts from its last known pose (a real robot reads
        its pose from its localisation instead).
        """
        me = self.options.agent
        snapshot = fetch_snapshot(session, self.keys.snapshot, self.limits, timeout=1.0)
        own = snapshot.applied.get(me) if snapshot is not None else None
        if snapshot is None or own is None:
            return False  # a fresh run: nothing of ours to resume
        self.replica.load(snapshot)
        contiguous, extras = own
        self.step = max((contiguous, *extras)) + 1
        pose = snapshot.poses.get(me)
        fetch(session, self.keys.all_relays, self.inbox, first=contiguous + 1, relayed=me)
        while (item := self.inbox.get(timeout=0)) is not None:
            if isinstance(item, Received) and isinstance(item.message, AgentStep) and item.message.agent == me:
                self.replica.apply(item.message.delta)
                if item.message.state.step >= self.step:
                    self.step = item.message.state.step + 1
                    pose = item.message.state.next_pose
            else:
                self.handle(item)
        if pose is not None and isinstance(self.robot, SimulatedUnicycle):
            self.robot = SimulatedUnicycle(pose, self.law)
        return True


def run_agent(scenario: Scenario, options: AgentOptions, config: zenoh.Config, stop: StopFlag) -> int:
    node = AgentNode(scenario, options)
    parent = os.getppid()
    keys = node.keys
    with open_session(config) as session:
        lockstep = options.clock == "lockstep"
        if lockstep:
            # Teammates' deltas arrive bundled in the coordinator's go: one message a step, not N − 1.
            session.declare_subscriber(keys.go, node.inbox.on_sample)
        else:
            # Remote only: our own deltas are applied when made, an echo would only cost a decode.
            session.declare_subscriber(keys.all_steps, node.inbox.on_sample, allowed_origin=zenoh.Locality.REMOTE)
            session.declare_subscriber(keys.objectives, node.inbox.on_sample)
            session.declare_queryable(keys.agent_relay(options.agent), node.relay.serve)
        session.declare_subscriber(keys.control, node.inbox.on_sample)
        session.liveliness().declare_subscriber(keys.alive_agents, node.inbox.on_liveliness, history=True)
        step_publisher = team_publisher(session, keys.agent_step(options.agent))
        token = session.liveliness().declare_token(keys.alive("agent", options.agent))
        settle_garbage_collector()

        history = History(keys.agent_history(options.agent))
        session.declare_queryable(keys.agent_history(options.agent), history.serve)
        session.declare_queryable(
            keys.agent_snapshot(options.agent),
            lambda query: query.reply(keys.agent_snapshot(options.agent), encode(node.replica.snapshot())),
        )
        loss = LossTimer()

        def publish(delta: MapDelta, state: AgentState) -> None:
            payload = encode(AgentStep(delta, state))  # one message a step: one send, one delivery each
            node.bytes_sent += len(payload)
            history.add(state.step, payload)
            step_publisher.put(payload)

        def recover_go() -> None:
            """A go (or the end of the run) that should be here is not: ask the coordinator's history."""
            fetch(session, keys.go_history, node.inbox, first=node.step)

        if node.resume_from_snapshot(session):
            # Lockstep: it says hello like a new robot, and the coordinator lists it again from its next go.
            node.rejoining = lockstep
            log.info("agent %d resumes from the coordinator's snapshot after step %d", options.agent, node.step - 1)
        # Wait for the first go, saying hello until the coordinator has heard it.
        next_hello = 0.0
        hellos = 0
        while not node.admitted() and node.finished is None and not stop.stopped:
            if time.monotonic() >= next_hello:
                step_publisher.put(encode(node.hello()))
                next_hello = time.monotonic() + HELLO_PERIOD
                hellos += 1
                if hellos == 1:
                    node.load_kernels()  # while the coordinator waits for the others' hellos
                if hellos % 5 == 0 and not node.rejoining:
                    recover_go()  # the first go may have been lost
            item = node.inbox.get(timeout=0.05)
            if item is not None:
                node.handle(item)
            if parent_is_gone(parent):
                break
        log.info("agent %d starts (%s clock)", options.agent, options.clock)
        period = scenario.dt / options.speed
        started = time.monotonic()
        next_gap_check = started + GAP_CHECK_PERIOD
        first_step = node.step
        while node.finished is None and not stop.stopped and not parent_is_gone(parent):
            if lockstep:
                waiting_since = last_news = time.monotonic()
                while not node.ready_for_step() and node.finished is None and not stop.stopped:
                    item = node.inbox.get(timeout=loss.patience)
                    if item is not None:
                        node.handle(item)
                        last_news = time.monotonic()
                    elif time.monotonic() - last_news >= loss.patience:
                        loss.recovering()
                        recover_go()
                        last_news = time.monotonic()
                    if time.monotonic() - waiting_since > 5.0:
                        log.info("agent %d still waiting at step %d: %s", options.agent, node.step, node.waiting_for())
                        waiting_since = time.monotonic()
                if node.finished is not None or stop.stopped:
                    break
                publish(*node.control_step())
                loss.step_done()
            else:
                while (item := node.inbox.get(timeout=0)) is not None:
                    node.handle(item)
                if node.finished is not None:
                    break
                if time.monotonic() >= next_gap_check:
                    fill_gaps(session, keys, node.replica, node.inbox)  # teammates' deltas lost on the way
                    fetch(session, keys.go_history, node.inbox, first=END_ONLY)  # the end of the run, if lost
                    next_gap_check = time.monotonic() + GAP_CHECK_PERIOD
                publish(*node.control_step())
                wait = started + (node.step - first_step) * period - time.monotonic()
                if wait > 0:
                    stop.wait(wait)
        # Let in-flight deltas of teammates land, so every replica ends with the same map.
        if node.finished is not None:
            node.inbox.drain(0.5, node.handle)
        final = node.finished.step if node.finished is not None and node.finished.kind == "done" else -1
        if lockstep and node.last_go < final and final not in node.gos:
            # The last go (every member's last delta) was lost and the end of the run came first: it is in
            # the coordinator's history.
            fetch(session, keys.go_history, node.inbox, first=node.step)
            while (item := node.inbox.get(timeout=0)) is not None:
                node.handle(item)
        if node.finished is not None and not lockstep:
            # Realtime: the last deltas of a teammate have no later one to reveal their loss; ask every
            # history for what follows our contiguous run, then stay a moment to answer the others' asks.
            teammates = [agent for agent in range(scenario.agents) if agent != options.agent]
            fill_gaps(session, keys, node.replica, node.inbox, to_the_end=teammates)
            node.inbox.drain(0.5, node.handle)
        node.apply_remaining_gos()
        token.undeclare()
    counts = (
        node.inbox.counts()
        | node.replica.counts()
        | {
            "steps": node.step,
            "bytes_sent": node.bytes_sent,
            "teammates_left": node.teammates_left,
        }
    )
    write_counts(Path(options.counts_file) if options.counts_file else None, counts)
    if node.finished is not None:
        log.info("agent %d: run %s at step %d", options.agent, node.finished.kind, node.finished.step)
        return EXIT_OK if node.finished.kind == "done" else EXIT_FAILED
    return stop.exit_code(EXIT_OK)
