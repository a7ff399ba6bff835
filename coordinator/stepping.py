"""The coordinator's main loop, one turn at a time, for either clock.

- lockstep: close steps in order as their deltas and states come in; each closed step k−1 becomes
  the go for step k, carrying every member's delta and state of step k−1 (and, on a replanning step,
  the objectives). A step whose message is late is asked of its sender's history.
- realtime: take whatever has come, fill known gaps now and then, log e_D for every step reached,
  and replan every ``replan_period`` of simulated time on the wall clock.

Either way the loop ends with an outcome (steps, completed, completion step) once the map is
complete, ``max_time`` is reached or no member is left.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from coordinator.endpoints import CoordinatorBus
from protocol.messages import Objectives, RunControl
from protocol.recovery import GAP_CHECK_PERIOD, LossTimer, fetch, fill_gaps

STATUS_PERIOD = 0.25
"""Seconds between progress messages on run/status."""

Outcome = tuple[int, bool, int]
"""(steps, completed, completion step)."""


@dataclass
class Stepping:
    bus: CoordinatorBus
    speed: float
    step: int = 0
    outcome: Outcome | None = None
    loss: LossTimer = field(default_factory=LossTimer)
    began: float = field(default_factory=time.monotonic)
    last_status: float = 0.0
    # Derived from the above when the loop begins:
    last_news: float = field(init=False)
    started: float = field(init=False)  # realtime: the wall-clock time of step 0
    next_plan: float = field(init=False)
    next_gap_check: float = field(init=False)

    def __post_init__(self) -> None:
        self.last_news = self.began
        self.started = self.began - self.step * self.bus.node.scenario.dt / self.speed
        self.next_plan = time.monotonic()
        self.next_gap_check = self.next_plan + GAP_CHECK_PERIOD

    def first_message(self, resumed: bool) -> None:
        """Lockstep: the go of step 0, from the hellos (not after a rebuild); realtime: the first objectives."""
        node = self.bus.node
        if node.lockstep and not resumed:
            node.closed_states = node.states_by_step.pop(-1, {})  # the hellos: where everyone starts
            self.bus.publish_go(node.go(0, []))
        elif not node.lockstep:
            self.bus.publish(self.bus.objectives, node.plan(0))

    def lockstep_turn(self) -> None:
        node = self.bus.node
        item = node.inbox.get(timeout=self.loss.patience)
        if item is not None:
            node.handle(item)
            self.last_news = time.monotonic()
        elif time.monotonic() - self.last_news >= self.loss.patience:
            self.loss.recovering()
            # Something of this step is missing (lost on the way): ask its sender's history.
            for agent in node.missing(self.step):
                fetch(self.bus.session, self.bus.keys.agent_history(agent), node.inbox, first=self.step, last=self.step)
            self.last_news = time.monotonic()
        while self.outcome is None and node.step_complete(self.step):
            # The replica now holds exactly Λ_{k+1}: every delta of steps ≤ k, none later.
            self.step += 1
            self.loss.step_done()
            node.log_step(self.step)
            if node.run_is_over(self.step):
                self.outcome = (self.step, node.replica.map.complete, self.step)
                # The last go only completes every replica; the agents then wait for the end.
                self.bus.publish_go(node.go(self.step, node.open_next_step(), final=True))
                break
            self.bus.publish_go(node.go(self.step, node.open_next_step()))

    def realtime_turn(self) -> None:
        node, scenario = self.bus.node, self.bus.node.scenario
        item = node.inbox.get(timeout=0.01)
        while item is not None:
            node.handle(item)
            item = node.inbox.get(timeout=0)
        if time.monotonic() >= self.next_gap_check:
            fill_gaps(self.bus.session, self.bus.keys, node.replica, node.inbox)
            self.next_gap_check = time.monotonic() + GAP_CHECK_PERIOD
        reached = max(node.latest_state_step.values(), default=-1) + 1
        while len(node.log.errors) <= reached:
            node.log_step(len(node.log.errors))
        if node.run_is_over(reached):
            node.log.errors[reached] = node.replica.map.domain_error()  # the map as it ends
            self.outcome = (reached, node.replica.map.complete, reached)
            return
        now = time.monotonic()
        if now >= self.next_plan:
            self.step = int((now - self.started) * self.speed / scenario.dt)
            plan = node.plan(0)  # as step 0 of a block: replan on every wall-clock period
            self.bus.publish(
                self.bus.objectives, Objectives(self.step, plan.members, plan.targets, plan.blobs, plan.labels)
            )
            self.next_plan = now + scenario.plan_steps * scenario.dt / self.speed

    def status_if_due(self) -> None:
        now = time.monotonic()
        if now - self.last_status >= STATUS_PERIOD:
            domain_error = self.bus.node.replica.map.domain_error()
            self.bus.publish(self.bus.status, RunControl("status", self.step, False, domain_error))
            self.last_status = now
