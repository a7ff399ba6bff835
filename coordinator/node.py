"""The coordinator's state between messages: membership, the open lockstep step, the planner.

Decisions only, no Zenoh session: the shell (:mod:`coordinator.process`, with endpoints, startup,
stepping and ending) moves messages in and out. It keeps its own
replica of the map, gathers every agent's state, runs the planner (the same
:class:`model.planning.Planner` as the in-process engine), closes lockstep steps in order, and admits
robots that return.
"""

from __future__ import annotations

import logging
import threading
from dataclasses import dataclass

import numpy as np

from coordinator.run_log import RunLog
from model.controllers import controller_of
from model.planning import watched_planner
from model.run import RunResult, snapshot_steps
from model.scenario import Scenario
from protocol.inbox import Inbox, Membership, Received
from protocol.keys import TeamKeys
from protocol.messages import AgentState, AgentStep, Limits, MapDelta, Objectives, StepGo, encode
from protocol.recovery import Relay
from protocol.replica import MapReplica

log = logging.getLogger("anicov.coordinator")


@dataclass
class CoordinatorOptions:
    team: str
    clock: str = "lockstep"
    speed: float = 1.0
    out: str | None = None
    drop_rate: float = 0.0
    await_logger: bool = False  # start only once a logger listens (so its recording has every step)


class Coordinator:
    def __init__(self, scenario: Scenario, options: CoordinatorOptions) -> None:
        self.scenario = scenario
        self.options = options
        self.keys = TeamKeys(options.team)
        self.limits = Limits.of(scenario)
        self.replica = MapReplica.of(scenario)
        self.planner = controller_of(scenario).planner(scenario)
        self.watched = watched_planner(scenario, self.planner)  # the progress watchdog around it (model.watchdog)
        self.inbox = Inbox(self.limits, options.drop_rate, seed=999)
        self.alive: set[int] = set()
        self.members: set[int] = set()
        self.positions: dict[int, tuple[float, float]] = {}
        self.latest_state_step: dict[int, int] = {}
        self.log = RunLog(scenario.agents)
        self.membership_changed = False
        self.targets = np.zeros((0, 2))
        self.bytes_sent = 0
        self.lockstep = options.clock == "lockstep"
        self.open_step: int | None = 0 if self.lockstep else None  # lockstep: the step being closed
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
            self.handle_locked(item)

    def handle_locked(self, item: Received | Membership) -> None:
        """``handle`` for a caller that holds the lock already."""
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
        """Apply a delta; in lockstep keep the open step's for the next go. In lockstep a delta of a step
        already closed can only be a departed agent's, come late (a step closes when every member's is
        in): no go can carry it any more, so it is dropped, not applied, or this replica alone would hold it."""
        if self.open_step is not None and delta.seq < self.open_step and not self.replica.has(delta.agent, delta.seq):
            self.log.events.append(f"a late delta of agent {delta.agent} for closed step {delta.seq} dropped")
            log.warning("agent %d's delta for step %d came after the step closed; dropped", delta.agent, delta.seq)
            return
        if self.replica.apply(delta) and delta.seq == self.open_step:
            self.open_deltas[delta.agent] = delta

    def plan_if_due(self, step: int) -> Objectives | None:
        """Objectives for a go: on a replanning step or after a change of members, else None."""
        if step % self.scenario.plan_steps == 0 or self.membership_changed:
            return self.plan(step)
        return None

    def go(self, step: int, deltas: list[MapDelta], final: bool = False) -> StepGo:
        """Lockstep: step ``step`` may start, with every member's previous delta and state (the closed
        step's). The final go only completes every replica: no objectives."""
        # Every delta of the closed step, a member's or not: each is in this replica already (an agent that
        # left after its delta came in still covered those cells), so every replica must have it too.
        kept = tuple(sorted(deltas, key=lambda d: d.agent))
        states = tuple(self.closed_states[agent] for agent in sorted(self.closed_states) if agent in self.members)
        objectives = self.plan_if_due(step) if self.members and not final else None
        return StepGo(step, tuple(sorted(self.members)), kept, objectives, states)

    def plan(self, step: int) -> Objectives:
        """Objectives for the members: Algorithms 1–2 anew on a replanning step or a change of members,
        else the current targets again."""
        members = sorted(self.members)
        positions = np.array([self.positions[agent] for agent in members], dtype=np.float64).reshape(-1, 2)
        if members and (
            step % self.scenario.plan_steps == 0 or self.membership_changed or len(self.targets) != len(members)
        ):
            lack = self.replica.map.lack_of_coverage()
            self.targets = self.watched.plan(step * self.scenario.dt, lack, positions, members)
            self.membership_changed = False
            return Objectives(step, tuple(members), self.targets, self.planner.blobs.positions, self.planner.labels())
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

    def log_step(self, step: int) -> None:
        """The replica holds Λ at t_step: log e_D, and a snapshot of Υ every SNAPSHOT_PERIOD."""
        self.log.errors.append(self.replica.map.domain_error())
        if step % snapshot_steps(self.scenario.dt) == 0:
            self.take_snapshot(step * self.scenario.dt)

    def run_is_over(self, step: int) -> bool:
        """The end of a run at ``step``: the map is complete, max_time is reached, no member is left, or on a
        replanning step (where the engine looks too) the watchdog has given up every cell left."""
        return (
            self.replica.map.complete
            or step >= self.scenario.max_steps
            or not self.members
            or (
                step % self.scenario.plan_steps == 0
                and self.watched.only_given_up_left(self.replica.map.lack_of_coverage())
            )
        )

    def take_snapshot(self, time_now: float) -> None:
        """Keep Υ at ``time_now`` (Fig. 6 and the recording)."""
        self.log.take_snapshot(time_now, self.replica.map.lack_of_coverage())

    def result(self, steps: int, completed: bool, completion_step: int) -> RunResult:
        """The run as the engine would return it, from what this coordinator saw."""
        result = self.log.result(self.scenario, steps, completed, completion_step, self.replica.map.lack_of_coverage())
        result.stalls, result.given_up = list(self.watched.stalls), self.watched.given_up()
        return result
