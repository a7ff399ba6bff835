"""One agent's decisions between messages: its replica of the map, the gos and objectives it has
received, who is in the team, and the control step itself. No Zenoh session: :mod:`agents.process`
opens one, feeds this class what arrives and publishes what it returns.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from agents.radio import RadioLink
from agents.robot import Robot, SimulatedUnicycle
from model.controllers import controller_of, law_parameters
from model.controllers.plugin_step import decide_with
from model.paper.coverage_map import load_kernels as load_map_kernels
from model.parameters import safety_parameters, starting_poses
from model.radio.exact_coverage import load_kernels as load_event_kernel
from model.safety.safety import MEMORY_SIZE, PARKED, POSE_STALE, RAN_LATE, TEAMMATE, filter_command
from model.safety.safety import load_kernels as load_safety_kernels
from model.scenario import Scenario
from model.step import LawParameters, decide_and_sense, load_kernels, no_look
from model.world.ground import NO_FIELD
from model.world.world import world_of
from protocol.events import as_event
from protocol.inbox import Inbox, Membership, Received
from protocol.keys import TeamKeys
from protocol.messages import AgentState, AgentStep, Limits, MapDelta, Objectives, Pose, RunControl, Snapshot, StepGo
from protocol.recovery import Relay
from protocol.replica import MapReplica

log = logging.getLogger("anicov.agent")


@dataclass
class AgentOptions:
    team: str
    agent: int
    clock: str = "lockstep"
    speed: float = 1.0
    drop_rate: float = 0.0
    counts_file: str | None = None
    deltas: str = "event"  # how this agent's deltas travel: "event" or "cells" (protocol.events)
    no_coordinator: bool = False  # a team without one (local planning, realtime): agree and start with the peers
    await_logger: bool = False  # with no coordinator: start only once a logger listens (its recording has every step)


class AgentNode:
    """The state of one agent process between messages."""

    def __init__(self, scenario: Scenario, options: AgentOptions, robot: Robot | None = None) -> None:
        self.scenario = scenario
        self.options = options
        self.keys = TeamKeys(options.team)
        self.limits = Limits.of(scenario)
        self.replica = MapReplica.of(scenario)
        self.controller = controller_of(scenario)
        self.law: LawParameters = law_parameters(scenario, self.replica.map)
        self.world = world_of(scenario)
        self.ground = self.world.ground
        starts = starting_poses(scenario)
        # Every robot's last known pose, for the line-of-sight test and the safety filter: all start where
        # the seed puts them. Realtime, the filter also needs how old each is (scenario time units).
        self.poses = starts.copy()
        self.positions = starts[:, :2].copy()
        self.heard_at = np.full(scenario.agents, time.monotonic())
        self.kinds = np.full(scenario.agents, TEAMMATE, dtype=np.int64)  # PARKED once a teammate's process is gone
        self.safety = safety_parameters(scenario)
        self.safety_memory = np.zeros(MEMORY_SIZE, dtype=np.int64)  # the filter's deadlock state (model.safety.safety)
        self.look = no_look()  # the cell the law looked at in the step before (model.world.wall_law.cell_to_look_at)
        self.robot = robot or SimulatedUnicycle(tuple(starts[options.agent]), self.law, self.ground)
        self.inbox = Inbox(self.limits, options.drop_rate, seed=1000 + options.agent)
        self.step = 0
        self.objective: tuple[float, float] | None = None
        self.started = False  # the coordinator has sent the first go or objectives
        self.gos: dict[int, StepGo] = {}  # lockstep: gos received for steps not yet taken
        self.last_go = -1  # lockstep: the step of the last go applied
        self.members_seen: set[int] = set()  # lockstep: the members of the last go applied
        self.rejoining = False  # lockstep: restarted, waiting for a go that lists this agent again
        self.finished: RunControl | None = None
        self.bytes_sent = 0  # payloads published
        self.bytes_served = 0  # replies to teammates' queries (history, relay, anti-entropy), set at the end
        self.created = time.monotonic()
        # Realtime: teammates' steps, for when one dies; with a limited radio the whole run's, for anti-entropy.
        self.radio = RadioLink(scenario, options.agent)  # comm_range and local planning
        self.relay = Relay(self.keys.agent_relay(options.agent), capacity=self.radio.relay_steps())
        self.teammates: set[int] = set()  # alive, by their liveliness tokens
        self.teammates_left: list[int] = []

    # ------------------------------------------------------------ messages

    def handle(self, item: Received | Membership) -> None:
        if isinstance(item, Membership):
            self.note_teammate(item)
            return
        message = item.message
        if isinstance(message, AgentStep):  # realtime: teammates' deltas, applied as they come
            if (
                message.agent != self.options.agent
                and item.live
                and not self.radio.hears(message.state, self.robot.pose())
            ):
                return  # the radio would not have carried it
            if message.agent != self.options.agent:
                self.replica.apply(message.delta)
                self.relay.add(message.agent, message.delta.seq, item.payload)
                self.note_position(message.state)
        elif isinstance(message, AgentState) and message.step < 0 and message.agent != self.options.agent:
            # Realtime, a teammate's hello: where its robot really is (a real base need not stand at the
            # seeded start), for the line of sight and the safety filter before its first step arrives.
            if not item.live or self.radio.hears(message, self.robot.pose()):
                self.note_position(message)
        elif isinstance(message, StepGo):
            if message.step >= self.step:
                self.gos[message.step] = message
            self.started = True
        elif isinstance(message, Objectives):
            if not self.started:
                self.heard_at[:] = time.monotonic()  # realtime: the team starts moving now
            if self.radio.planner is None:
                self.take_targets(message)
            self.started = True
        elif isinstance(message, RunControl) and message.kind in ("done", "abort"):
            self.finished = message

    def handle_queued(self) -> None:
        """Everything already in the inbox, without waiting for more."""
        while (item := self.inbox.get(timeout=0)) is not None:
            self.handle(item)

    def note_teammate(self, change: Membership) -> None:
        """A teammate's liveliness token came or went. The coordinator replans for the team; a robot
        logs it (a dead teammate's lost deltas then come from the relays, see protocol.recovery.fill_gaps)."""
        if change.agent == self.options.agent:
            return
        if 0 <= change.agent < len(self.kinds):
            self.kinds[change.agent] = TEAMMATE if change.alive else PARKED  # a dead robot's base stops
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
            self.apply_teammates(self.gos.pop(step).deltas)

    def apply_teammates(self, deltas: tuple[MapDelta, ...]) -> None:
        """A go's deltas, but our own: that one entered the replica when we made it."""
        for delta in deltas:
            if delta.agent != self.options.agent:
                self.replica.apply(delta)

    def park(self, agents: set[int]) -> None:
        """Realtime: teammates done for good (protocol.settling) stand as bodies, not as poses growing old."""
        for agent in agents & set(range(len(self.kinds))) - {self.options.agent}:
            self.kinds[agent] = PARKED

    def note_position(self, state: AgentState) -> None:
        """A teammate's pose at the end of its step (lockstep: every member's, at the start of this step).
        A step its robot held for want of a pose (POSE_STALE) repeats the last known one: it does not make
        that pose any younger, so the safety filter's age of it keeps growing."""
        if 0 <= state.agent < len(self.positions) and state.agent != self.options.agent:
            self.positions[state.agent] = state.next_pose[:2]
            self.poses[state.agent] = state.next_pose
            if not state.safety & POSE_STALE:
                self.heard_at[state.agent] = time.monotonic()

    # ------------------------------------------------------------ radio (issue 13, agents/radio.py)

    def plan_locally(self, members: list[int], pose: Pose) -> None:
        """planning = "local": our own objective from our replica (see RadioLink.local_objective)."""
        lack = self.replica.map.lack_of_coverage()
        self.objective = self.radio.local_objective(members, pose, self.positions, lack, self.step)

    def ends_on_its_own(self) -> bool:
        """Realtime, local planning: end the run here when RadioLink.ends_now says so."""
        if self.finished is None and self.radio.ends_now(self.replica.map, self.options.no_coordinator):
            log.info(
                "agent %d: its replica is complete (or all it has left was given up by its watchdog) and no "
                "coordinator ended the run: it ends",
                self.options.agent,
            )
            self.finished = RunControl("done", self.step, True, self.replica.map.domain_error(), reason="local")
            return True
        return False

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
        self.apply_teammates(go.deltas)
        for state in go.states:
            self.note_position(state)
        if go.objectives is not None:
            if self.radio.planner is None:
                self.take_targets(go.objectives)
            else:  # when the coordinator would plan, with the go's members (their poses are t_k's)
                self.plan_locally(list(go.members), self.robot.pose())
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
            self.apply_teammates(self.gos.pop(earlier).deltas)
        self.replica.skip(self.options.agent, step - 1)
        self.members_seen = set(self.gos[step].members)
        self.step = step
        self.rejoining = False

    def waiting_for(self) -> str:
        """What a lockstep step is waiting on, for the log."""
        return f"the coordinator's go for step {self.step}"

    def lost_last_go(self) -> bool:
        """Lockstep, at the end of a run: the last go (every member's last delta) has not arrived,
        though the end of the run has (so it was lost, or is late)."""
        final = self.finished.step if self.finished is not None and self.finished.kind == "done" else -1
        return self.last_go < final and final not in self.gos

    def others(self) -> list[int]:
        """Every other agent of the team, alive or not."""
        return [agent for agent in range(self.scenario.agents) if agent != self.options.agent]

    # ------------------------------------------------------------ control

    def control_step(self, late: bool = False) -> tuple[MapDelta, AgentState]:
        """Decide, sense and move for the current step (eq. 1–16); return what to publish.

        ``late`` (realtime, with the safety filter): the loop fell a period or more behind its clock, so
        this step is taken standing still. A robot catching up at full speed would move faster than
        k_v in wall time, beyond what its teammates' margins allow for (a real base's watchdog stops it)."""
        pose = self.robot.current_pose()
        me = self.options.agent
        if pose is None:
            return self.hold_step(self.robot.pose())
        if self.options.clock == "realtime" and self.radio.plan_due(self.step):
            self.plan_locally(self.radio.in_contact(), pose)
        if self.objective is None:
            # Realtime, an agent restarted from the coordinator's snapshot whose clock ran before the next
            # objectives came: it stands still and senses nothing until they do (it crashed here on an
            # AssertionError, a fresh clone's suite, 2026-12-06). In lockstep the go always follows a plan.
            return self.hold_step(pose)
        self.positions[me] = pose[:2]
        if self.controller.compiled:
            field = self.world.field(*self.objective) if self.ground.walls else NO_FIELD
            v, omega, e_omega, row0, col0, ticks = decide_and_sense(
                self.replica.map.coverage, *pose, *self.objective, self.law, self.ground, field, self.positions, me,
                self.look,
            )  # fmt: skip
        else:  # a controller written in Python: the engine's call (anicov.plugin_engine), so lockstep equals it
            v, omega, e_omega, row0, col0, ticks = decide_with(
                self.controller, self.scenario, self.step, self.replica.map.coverage, pose, self.objective, self.law,
                self.ground, self.positions, me,
            )  # fmt: skip
        flags = 0
        if self.safety.enabled and late:
            v, omega, flags = 0.0, 0.0, RAN_LATE
        elif self.safety.enabled:
            self.poses[me] = pose
            v, omega, flags = filter_command(
                v,
                omega,
                me,
                self.radio.beyond_reach(self.poses, self.kinds),
                self.pose_ages(),
                self.kinds,
                self.ground,
                self.law.cell,
                self.safety,
                self.safety_memory,
            )
        delta = MapDelta(self.options.agent, self.step, row0, col0, ticks)
        if self.options.deltas == "event":
            delta = as_event(delta, pose, self.limits.kernel)
        self.replica.apply(delta)
        next_pose = self.robot.command(v, omega)
        v, omega = self.robot.last_command  # a real base's limits may have cut it
        stamp = time.time() if self.options.clock == "realtime" else 0.0  # a team clock for the safety record
        state = AgentState(self.options.agent, self.step, pose, v, omega, e_omega, next_pose, flags, stamp)
        self.step += 1
        return delta, state

    def hold_step(self, pose: Pose) -> tuple[MapDelta, AgentState]:
        """A step without a current pose (a real base whose odometry stopped), or without an objective yet: the
        robot is sent zero and senses nothing; the step still counts so the sequence goes on."""
        next_pose = self.robot.command(0.0, 0.0)
        delta = MapDelta(self.options.agent, self.step, 0, 0, np.zeros((0, 0), dtype=np.int64))
        self.replica.apply(delta)
        state = AgentState(self.options.agent, self.step, pose, 0.0, 0.0, 0.0, next_pose, POSE_STALE, time.time())
        self.step += 1
        return delta, state

    def pose_ages(self) -> np.ndarray:
        """How old each teammate's pose is, in scenario time: 0 in lockstep (every pose is t_k's, from the
        go); realtime, the wall time since it arrived, at the run's speed."""
        if self.options.clock == "lockstep":
            return np.zeros(len(self.poses))
        return (time.monotonic() - self.heard_at) * self.options.speed

    def load_kernels(self) -> None:
        """numba's kernels loaded while the team gathers (see model.step.load_kernels)."""
        load_kernels(self.replica.map.coverage, self.robot.pose(), self.law, self.ground)
        load_safety_kernels(self.safety, self.ground, self.law.cell, self.scenario.agents)
        load_map_kernels()
        load_event_kernel(self.limits.kernel)

    def hello(self) -> AgentState:
        pose = self.robot.pose()
        return AgentState(self.options.agent, -1, pose, 0.0, 0.0, 0.0, pose)

    # ------------------------------------------------------------ restart

    def load_snapshot(self, snapshot: Snapshot) -> int | None:
        """A restarted robot: if the coordinator's snapshot knows this agent, resume where it stopped.

        The map and the applied sequences come from the snapshot (deltas arriving
        meanwhile are applied once). The last steps before the crash may have
        reached teammates but not the coordinator: the process fetches them from
        the relays, from the sequence returned here, into the inbox, and
        :meth:`finish_resume` takes them, so that no sequence is ever used for
        two different deltas. None: the snapshot knows nothing of ours (a fresh run).
        """
        own = snapshot.applied.get(self.options.agent)
        if own is None:
            return None
        self.replica.load(snapshot)
        contiguous, extras = own
        self.step = max((contiguous, *extras)) + 1
        return contiguous + 1

    def finish_resume(self, pose: Pose | None) -> None:
        """After :meth:`load_snapshot` and the relays' answers: the step continues after this agent's
        last delta anyone holds, and the simulated robot restarts from its last known pose (``pose``,
        the snapshot's, unless a relayed step is later; a real robot reads its pose from its
        localisation instead). Anything else queued meanwhile is handled as usual."""
        me = self.options.agent
        while (item := self.inbox.get(timeout=0)) is not None:
            if isinstance(item, Received) and isinstance(item.message, AgentStep) and item.message.agent == me:
                self.replica.apply(item.message.delta)
                if item.message.state.step >= self.step:
                    self.step = item.message.state.step + 1
                    pose = item.message.state.next_pose
            else:
                self.handle(item)
        if pose is not None and isinstance(self.robot, SimulatedUnicycle):
            self.robot = SimulatedUnicycle(pose, self.law, self.ground)

    # ------------------------------------------------------------ end

    def counts(self) -> dict[str, object]:
        """What this agent reports at exit (tests compare them across processes)."""
        return (
            self.inbox.counts()
            | self.replica.counts()
            | {
                "steps": self.step,
                "bytes_sent": self.bytes_sent,
                "bytes_served": self.bytes_served,
                "wall_seconds": round(time.monotonic() - self.created, 3),
                "teammates_left": self.teammates_left,
                "out_of_range": self.radio.out_of_range,
                "domain_error": self.replica.map.domain_error(),
            }
        )
