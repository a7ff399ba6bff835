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
from model.world import world_of
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


def peer_digests(session: zenoh.Session, keys: TeamKeys, limits: Limits, timeout: float) -> dict[int, ScenarioDigest]:
    """A team with no coordinator: the digest of every agent that answers on agent/<id>/scenario."""
    found: dict[int, ScenarioDigest] = {}
    for reply in session.get(keys.all_agent_scenarios, timeout=timeout):
        if reply.ok is None:
            continue
        agent = agent_of_key(str(reply.ok.key_expr))
        try:
            message = decode(reply.ok.payload.to_bytes(), limits, expected="scenario")
        except ProtocolError as error:
            log.warning("rejected a teammate's scenario digest: %s", error)
            continue
        if agent is not None and 0 <= agent < limits.agents:
            assert isinstance(message, ScenarioDigest)
            found[agent] = message
    return found


def coordinator_digest(session: zenoh.Session, keys: TeamKeys, limits: Limits, timeout: float) -> ScenarioDigest | None:
    """The coordinator's digest, or None if no coordinator answered within ``timeout`` seconds."""
    for reply in session.get(keys.scenario, timeout=timeout):
        if reply.ok is None:
            continue
        try:
            message = decode(reply.ok.payload.to_bytes(), limits, expected="scenario")
        except ProtocolError as error:
            log.warning("rejected the coordinator's scenario digest: %s", error)
            continue
        assert isinstance(message, ScenarioDigest)
        return message
    return None


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
