"""One robot's side of a limited radio (issue 13, :mod:`model.radio.radio` for the rule): whom it hears, who is
in contact, and local planning. The agent node owns one :class:`RadioLink`; no Zenoh here."""

from __future__ import annotations

import math
import time

import numpy as np

from model.controllers import controller_of
from model.paper.coverage_map import CoverageMap
from model.planning import watched_planner
from model.safety.safety import TEAMMATE
from model.scenario import Scenario
from protocol.messages import AgentState, Pose
from protocol.recovery import HISTORY_STEPS, RELAY_STEPS

CONTACT_SECONDS = 1.0
"""comm_range, realtime: a teammate heard live within this many wall seconds is in contact."""
LOCAL_END_WAIT = 2.0
"""Local planning, realtime: wall seconds a complete replica waits for the coordinator's end of the run."""


class RadioLink:
    """What the radio lets a robot know of its teammates, and its own planner when planning is local."""

    def __init__(self, scenario: Scenario, me: int) -> None:
        self.scenario = scenario
        self.me = me
        self.heard_live = np.full(scenario.agents, -np.inf)  # when each teammate was last heard (monotonic)
        self.out_of_range = 0  # teammates' steps the radio did not deliver
        # Whose latest step came from beyond comm_range: the safety filter leaves them out (see beyond_reach).
        self.last_beyond = np.zeros(scenario.agents, dtype=bool)
        # Local planning: the robot's own planner, with its own progress watchdog (model.watchdog).
        local = scenario.planning == "local"
        self.planner = watched_planner(scenario, controller_of(scenario).planner(scenario)) if local else None
        self.planned_at = -(10**9)  # local planning: the step of the last plan
        self.complete_since: float | None = None  # local planning, realtime: when our replica became complete

    def history_steps(self) -> int:
        """How many of its own steps a robot keeps: the whole run (a restarted coordinator rebuilds from
        step 0, and anti-entropy may ask for any)."""
        return max(HISTORY_STEPS, self.scenario.max_steps)

    def relay_steps(self) -> int:
        """How many steps of each teammate a robot keeps to serve again: the last few with every teammate
        in range; the whole run where anti-entropy may ask for any."""
        return self.history_steps() if math.isfinite(self.scenario.comm_range) else RELAY_STEPS

    def hears(self, state: AgentState, pose: Pose) -> bool:
        """The receiver's radio filter: a teammate's step (or hello) arrives only from within ``comm_range``
        (its pose at that step against ours, ``pose``, now). Heard, it counts as contact."""
        if math.isfinite(self.scenario.comm_range):
            beyond = math.hypot(state.pose[0] - pose[0], state.pose[1] - pose[1]) > self.scenario.comm_range
            if 0 <= state.agent < len(self.last_beyond):
                self.last_beyond[state.agent] = beyond
            if beyond:
                self.out_of_range += 1
                return False
        if 0 <= state.agent < len(self.heard_live):
            self.heard_live[state.agent] = time.monotonic()
        return True

    def beyond_reach(self, poses: np.ndarray, kinds: np.ndarray) -> np.ndarray:
        """The teammates' poses for the safety filter, a teammate whose latest step came from beyond comm_range
        left out (NaN). Its last heard pose ages while it is away, and the filter stops a robot for a pose in
        reach older than max_pose_age: a teammate that walked out of range stopped the team for ever. Its
        steps still come, dropped by the range: it is farther than comm_range, which is at least safety_range
        (the scenario check), the filter's reach. A parked teammate (dead, or done: its base stands) is always
        shown: it no longer sends steps that could say where it is."""
        away = self.last_beyond & (kinds == TEAMMATE)
        if not away.any():
            return poses
        seen = poses.copy()
        seen[away] = np.nan
        return seen

    def in_contact(self) -> list[int]:
        """Teammates heard live within the last CONTACT_SECONDS, by id."""
        recent = time.monotonic() - CONTACT_SECONDS
        return [agent for agent in range(self.scenario.agents) if agent != self.me and self.heard_live[agent] >= recent]

    def plan_due(self, step: int) -> bool:
        """Realtime, local planning: a plan every plan period of the controller (the paper's law: replan_period;
        anicov: a carrot every CARROT_PERIOD), and at the first step."""
        return self.planner is not None and step - self.planned_at >= self.scenario.plan_steps

    def local_objective(
        self, members: list[int], pose: Pose, positions: np.ndarray, lack: np.ndarray, step: int
    ) -> tuple[float, float]:
        """planning = "local": Algorithms 1-2 on our own replica's Υ (``lack``) for ``members`` and us, at
        their last known ``positions`` (ours: ``pose``); our own objective (model.radio.radio, local planning)."""
        assert self.planner is not None
        members = sorted(set(members) | {self.me})
        where = np.array([pose[:2] if agent == self.me else positions[agent] for agent in members])
        targets = self.planner.plan(step * self.scenario.dt, lack, where, members)
        self.planned_at = step
        mine = targets[members.index(self.me)]
        return float(mine[0]), float(mine[1])

    def ends_now(self, replica: CoverageMap, alone: bool) -> bool:
        """Local planning: our ``replica`` is complete (so the world is), or, in a team with no coordinator
        (``alone``), our watchdog gave up every cell it has left, and has been for LOCAL_END_WAIT seconds
        without the coordinator ending the run (it is gone). With a coordinator, its watchdog ends the run:
        ours may give up a cell a teammate's or the coordinator's does not."""
        if self.planner is None:
            return False
        given_up = self.planner.given_up() if alone else None
        if not replica.complete and (
            given_up is None or not given_up.any() or not self.planner.only_given_up_left(replica.lack_of_coverage())
        ):
            return False
        now = time.monotonic()
        if self.complete_since is None:
            self.complete_since = now
        return now - self.complete_since >= LOCAL_END_WAIT
