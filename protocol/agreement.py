"""Every process of a team runs the same scenario on the same map, or refuses to start.

Each process loads the scenario (and its map) from its own files. The coordinator serves a
:class:`~protocol.messages.ScenarioDigest` at ``coordinator/scenario``: sha256 of the scenario's keys
(file paths left out: hosts keep their files in different places) and of its map's YAML and image.
An agent asks for it before it says hello, and the logger before it records; on a mismatch the process
stops with an error naming both digests and the files, before it touches the team's run.
"""

from __future__ import annotations

import hashlib
import json
import logging

import zenoh

from model.scenario import Scenario
from model.world.world import world_of
from protocol.decoding import decode
from protocol.keys import TeamKeys, agent_of_key
from protocol.messages import Limits, ProtocolError, ScenarioDigest, encode

log = logging.getLogger("anicov.agreement")


class ScenarioMismatch(RuntimeError):
    """This process's scenario or map is not the coordinator's."""


def digest_of(scenario: Scenario) -> ScenarioDigest:
    """The digest of a scenario as this process loaded it."""
    world = world_of(scenario)
    keys = {key: value for key, value in scenario.to_dict().items() if key != "map"}
    if scenario.priority_map:
        keys["lambda_star"] = world.priority_sha256
    text = json.dumps(keys, sort_keys=True) + world.map_sha256
    return ScenarioDigest(hashlib.sha256(text.encode()).hexdigest(), world.map_sha256)


def serve_digest(session: zenoh.Session, key: str, digest: ScenarioDigest) -> zenoh.Queryable:
    """Answer every ask on ``key`` (the coordinator's, or an agent's own) with this process's digest."""
    payload = encode(digest)
    return session.declare_queryable(key, lambda query: query.reply(key, payload))


def _digests(
    session: zenoh.Session, key: str, limits: Limits, timeout: float, whose: str
) -> list[tuple[str, ScenarioDigest]]:
    """Every valid digest answered on ``key`` within ``timeout`` seconds, with the key it came on; a
    malformed answer is logged and left out."""
    found = []
    for reply in session.get(key, timeout=timeout):
        if reply.ok is None:
            continue
        try:
            message = decode(reply.ok.payload.to_bytes(), limits, expected="scenario")
        except ProtocolError as error:
            log.warning("rejected %s scenario digest: %s", whose, error)
            continue
        assert isinstance(message, ScenarioDigest)
        found.append((str(reply.ok.key_expr), message))
    return found


def peer_digests(session: zenoh.Session, keys: TeamKeys, limits: Limits, timeout: float) -> dict[int, ScenarioDigest]:
    """A team with no coordinator: the digest of every agent that answers on agent/<id>/scenario."""
    found: dict[int, ScenarioDigest] = {}
    for key, digest in _digests(session, keys.all_agent_scenarios, limits, timeout, "a teammate's"):
        agent = agent_of_key(key)
        if agent is not None and 0 <= agent < limits.agents:
            found[agent] = digest
    return found


def check_peers(mine: ScenarioDigest, found: dict[int, ScenarioDigest], scenario: Scenario) -> None:
    """Raise ScenarioMismatch at the first teammate (by id) that does not run what this process loaded."""
    for agent, theirs in sorted(found.items()):
        check_agreement(mine, theirs, scenario, whose=f"agent {agent}'s")


def coordinator_digest(session: zenoh.Session, keys: TeamKeys, limits: Limits, timeout: float) -> ScenarioDigest | None:
    """The coordinator's digest, or None if no coordinator answered within ``timeout`` seconds."""
    found = _digests(session, keys.scenario, limits, timeout, "the coordinator's")
    return found[0][1] if found else None


def check_agreement(
    mine: ScenarioDigest, theirs: ScenarioDigest, scenario: Scenario, whose: str = "the coordinator's"
) -> None:
    """Raise ScenarioMismatch unless the coordinator (or ``whose`` process) runs what this process loaded."""
    if mine == theirs:
        return
    if mine.map_sha256 != theirs.map_sha256:
        raise ScenarioMismatch(
            f"map {scenario.map or '(none)'} has sha256 {mine.map_sha256[:16] or '-'}..., {whose} "
            f"map has {theirs.map_sha256[:16] or '-'}...: give every process the same map files"
        )
    raise ScenarioMismatch(
        f"scenario digest {mine.scenario[:16]}... differs from {whose} {theirs.scenario[:16]}...: "
        "give every process the same scenario file and overrides (--n, --seed, --controller)"
    )
