"""Zenoh key expressions of a team. Everything lives under ``anicov/<team>/``.

key (under anicov/<team>/)  message              from → to           what
agent/<id>/step             AgentStep            agent → all         one step: coverage added, pose, (v, ω), e_Ω
                            AgentState           agent → all         hello (step −1): its pose at t_0
agent/<id>/history          (queryable)          agent               its recent steps
agent/<id>/snapshot         (queryable)          agent               its replica: for a restarted coordinator
agent/<id>/relay            (queryable)          agent               realtime: teammates' recent steps, served
                                                                     for one that died (?agent=<id>;steps=…)
agent/<id>/sync             (queryable)          agent               comm_range: anti-entropy, ?have=<c0>,<c1>,…
                                                                     → every step it holds beyond those counts
agent/<id>/scenario         (queryable)          agent               ScenarioDigest: what it runs (for a team
                                                                     with no coordinator: peers check each other)
coordinator/go              StepGo               coordinator → all   lockstep: step k may start, with every
                                                                     step k−1 delta and state, targets on replans
coordinator/objectives      Objectives           coordinator → all   realtime: the latest targets
coordinator/snapshot        (queryable)          coordinator         map, sequences, poses: late joiners
coordinator/history         (queryable)          coordinator         recent gos and the end of the run
coordinator/scenario        (queryable)          coordinator         ScenarioDigest: what it runs (map sha256)
coordinator/relay           (queryable)          coordinator         realtime: as agent/<id>/relay
run/control                 RunControl           coordinator → all   run done / aborted
run/status                  RunControl           coordinator → all   progress (e_D, step)
traffic/<role>/<id>         Traffic              every process       bytes out and in so far, each second
alive/<role>/<id>           liveliness token     every process       agent/<id>, coordinator/0, logger/0
ending/<phase>/<role>/<id>  liveliness token     agent, coordinator  realtime end of run: stopped (no more
                                                                     deltas), whole (replica has them all);
                                                                     see protocol.settling
"""

from __future__ import annotations

import re
from dataclasses import dataclass

ROOT = "anicov"
_TEAM_NAME = re.compile(r"^[A-Za-z0-9_-]{1,64}$")


def check_team_name(team: str) -> str:
    """A team name is 1–64 letters, digits, '-' or '_' (no key-expression wildcards)."""
    if not _TEAM_NAME.match(team):
        raise ValueError(f"team name {team!r}: expected 1-64 characters from A-Z a-z 0-9 _ -")
    return team


@dataclass(frozen=True)
class TeamKeys:
    team: str

    def __post_init__(self) -> None:
        check_team_name(self.team)

    @property
    def prefix(self) -> str:
        return f"{ROOT}/{self.team}"

    def agent_step(self, agent: int) -> str:
        return f"{self.prefix}/agent/{agent}/step"

    def agent_snapshot(self, agent: int) -> str:
        return f"{self.prefix}/agent/{agent}/snapshot"

    def agent_history(self, agent: int) -> str:
        return f"{self.prefix}/agent/{agent}/history"

    def agent_relay(self, agent: int) -> str:
        return f"{self.prefix}/agent/{agent}/relay"

    def agent_sync(self, agent: int) -> str:
        return f"{self.prefix}/agent/{agent}/sync"

    def agent_scenario(self, agent: int) -> str:
        return f"{self.prefix}/agent/{agent}/scenario"

    @property
    def all_agent_scenarios(self) -> str:
        return f"{self.prefix}/agent/*/scenario"

    @property
    def coordinator_relay(self) -> str:
        return f"{self.prefix}/coordinator/relay"

    @property
    def all_relays(self) -> str:
        return f"{self.prefix}/**/relay"

    @property
    def all_histories(self) -> str:
        return f"{self.prefix}/agent/*/history"

    @property
    def scenario(self) -> str:
        return f"{self.prefix}/coordinator/scenario"

    @property
    def go_history(self) -> str:
        return f"{self.prefix}/coordinator/history"

    @property
    def all_steps(self) -> str:
        return f"{self.prefix}/agent/*/step"

    @property
    def objectives(self) -> str:
        return f"{self.prefix}/coordinator/objectives"

    @property
    def go(self) -> str:
        return f"{self.prefix}/coordinator/go"

    @property
    def snapshot(self) -> str:
        return f"{self.prefix}/coordinator/snapshot"

    @property
    def control(self) -> str:
        return f"{self.prefix}/run/control"

    @property
    def status(self) -> str:
        return f"{self.prefix}/run/status"

    def traffic(self, role: str, ident: int = 0) -> str:
        return f"{self.prefix}/traffic/{role}/{ident}"

    @property
    def all_traffic(self) -> str:
        return f"{self.prefix}/traffic/**"

    def alive(self, role: str, ident: int = 0) -> str:
        return f"{self.prefix}/alive/{role}/{ident}"

    @property
    def alive_agents(self) -> str:
        return f"{self.prefix}/alive/agent/*"

    @property
    def alive_everyone(self) -> str:
        return f"{self.prefix}/alive/*/*"

    def ending(self, phase: str, role: str, ident: int = 0) -> str:
        return f"{self.prefix}/ending/{phase}/{role}/{ident}"

    @property
    def all_endings(self) -> str:
        return f"{self.prefix}/ending/*/*/*"

    @property
    def everything(self) -> str:
        return f"{self.prefix}/**"


def agent_of_key(key: str) -> int | None:
    """The agent id in ``.../agent/<id>/...`` or ``.../alive/agent/<id>``, if any and well-formed."""
    parts = key.split("/")
    for index, part in enumerate(parts[:-1]):
        if part == "agent" and parts[index + 1].isdigit() and len(parts[index + 1]) <= 6:
            return int(parts[index + 1])
    return None
