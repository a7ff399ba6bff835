"""Decoding with validation: a payload becomes a typed message, or a :class:`ProtocolError` with a short,
countable reason. Everything a receiver relies on is checked (version, type, field types, shapes,
finite numbers, ids in range, map windows inside the grid, non-negative deltas); nothing that fails
here may touch a map or a controller.
"""

from __future__ import annotations

import math
import struct
import time
import zlib
from collections.abc import Callable
from typing import Any

import msgpack
import numpy as np

from model.radio.exact_coverage import event_window
from protocol.events import delta_of_event
from protocol.messages import (
    COMPACT_COUNT,
    COMPACT_FIX,
    COMPACT_HEAD,
    COMPACT_STAMP,
    COMPACT_STEP,
    FIXED,
    MAX_PAYLOAD_BYTES,
    NOTHING_SENSED,
    PROTOCOL_VERSION,
    RUN_CONTROL_KINDS,
    STAMP_UNITS,
    STAMPED,
    TRAFFIC_ROLES,
    AgentState,
    AgentStep,
    Limits,
    MapDelta,
    Message,
    Objectives,
    Pose,
    ProtocolError,
    RunControl,
    ScenarioDigest,
    SensingEvent,
    Snapshot,
    StepGo,
    Traffic,
)


def _int(body: dict[str, Any], key: str, low: int, high: int) -> int:
    value = body.get(key)
    if isinstance(value, bool) or not isinstance(value, int):
        raise ProtocolError("bad-field", f"{key} must be an integer")
    if not low <= value <= high:
        raise ProtocolError("out-of-range", f"{key}={value} not in [{low}, {high}]")
    return value


def _finite(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ProtocolError("not-finite", f"{name} must be a finite number")
    return float(value)


def _floats(body: dict[str, Any], key: str, length: int | None = None) -> list[float]:
    value = body.get(key)
    if not isinstance(value, list) or (length is not None and len(value) != length):
        raise ProtocolError("bad-shape", f"{key} must be a list" + (f" of {length}" if length else ""))
    return [_finite(item, key) for item in value]


def _header(payload: bytes) -> dict[str, Any]:
    if not isinstance(payload, bytes | bytearray | memoryview):
        raise ProtocolError("not-bytes")
    if len(payload) > MAX_PAYLOAD_BYTES:
        raise ProtocolError("too-large", f"{len(payload)} bytes")
    try:
        body = msgpack.unpackb(payload, raw=False, strict_map_key=True, max_bin_len=MAX_PAYLOAD_BYTES)
    except Exception as error:  # msgpack raises several unrelated types on garbage
        raise ProtocolError("undecodable", type(error).__name__) from None
    if not isinstance(body, dict):
        raise ProtocolError("not-a-map")
    if body.get("v") != PROTOCOL_VERSION:
        raise ProtocolError("bad-version", f"expected {PROTOCOL_VERSION}, got {body.get('v')!r}")
    return body


MAX_STEP = 2**40


def _inflate(packed: Any, size: int, name: str) -> bytes:
    """Decompress a zlib field that must hold exactly ``size`` bytes (and never inflates past it)."""
    if not isinstance(packed, bytes):
        raise ProtocolError("bad-field", f"{name} must be bytes")
    try:
        raw = zlib.decompressobj().decompress(packed, size + 1)
    except zlib.error:
        raise ProtocolError("undecodable", f"{name} is not zlib data") from None
    if len(raw) != size:
        raise ProtocolError("bad-shape", f"{name} must hold {size} bytes")
    return raw


def _members(body: dict[str, Any], last_agent: int) -> list[int]:
    """A list of distinct agent ids in range."""
    members = body.get("members")
    if not isinstance(members, list) or any(isinstance(m, bool) or not isinstance(m, int) for m in members):
        raise ProtocolError("bad-field", "members must be a list of integers")
    if any(not 0 <= m <= last_agent for m in members) or len(set(members)) != len(members):
        raise ProtocolError("out-of-range", "members must be distinct agent ids")
    return members


MAX_EVENT_COORDINATE = 2.0**20
"""An event's x, y (and θ) beyond this are refused: the integer kernel holds positions up to 2²⁰ units."""
MAX_TICKS = 2**40


def _decode_event(body: dict[str, Any], limits: Limits, agent: int, seq: int) -> MapDelta:
    """A delta sent as its sensing event (protocol.events): the pose, then the fixes, checked against the
    integer kernel's window before anything is computed from them."""
    if limits.kernel is None:
        raise ProtocolError("no-kernel", "this team's deltas cannot travel as events")
    x, y, theta = _floats(body, "ev", 3)
    if max(abs(x), abs(y), abs(theta)) > MAX_EVENT_COORDINATE:
        raise ProtocolError("out-of-range", "an event's pose lies too far out")
    row0, row1, col0, col1 = event_window(limits.kernel, x, y)
    cells = max(row1 - row0, 0) * max(col1 - col0, 0)
    numbers = body.get("fix")
    if not isinstance(numbers, list) or len(numbers) % 2 or len(numbers) > 2 * cells:
        raise ProtocolError("bad-shape", "fix must be [index, ticks, ...], at most one per window cell")
    fixes = []
    for k in range(0, len(numbers), 2):
        low = fixes[-1][0] + 1 if fixes else 0
        index = _int({"index": numbers[k]}, "index", low, cells - 1)
        fixes.append((index, _int({"ticks": numbers[k + 1]}, "ticks", 0, MAX_TICKS)))
    return delta_of_event(agent, seq, SensingEvent((x, y, theta), tuple(fixes)), limits.kernel)


def _decode_delta(body: dict[str, Any], limits: Limits) -> MapDelta:
    last_agent = limits.agents - 1
    agent = _int(body, "agent", 0, last_agent)
    seq = _int(body, "seq", 0, MAX_STEP)
    if "ev" in body:
        return _decode_event(body, limits, agent, seq)
    height = _int(body, "h", 0, limits.rows)
    width = _int(body, "w", 0, limits.cols)
    row0 = _int(body, "row0", 0, limits.rows)
    col0 = _int(body, "col0", 0, limits.cols)
    if row0 + height > limits.rows or col0 + width > limits.cols:
        raise ProtocolError("window-outside-grid", f"{height}x{width} at ({row0}, {col0})")
    raw = body.get("ticks")
    if not isinstance(raw, bytes) or len(raw) != 8 * height * width:
        raise ProtocolError("bad-shape", "ticks must hold h*w int64")
    ticks = np.frombuffer(raw, dtype="<i8").reshape(height, width).astype(np.int64)
    if (ticks < 0).any():
        raise ProtocolError("negative-delta")
    return MapDelta(agent, seq, row0, col0, ticks)


def _decode_state(body: dict[str, Any], limits: Limits) -> AgentState:
    pose = _floats(body, "pose", 3)
    vel = _floats(body, "vel", 2)
    nxt = _floats(body, "next", 3)
    e_omega = _finite(body.get("e_omega"), "e_omega")
    if not 0.0 <= e_omega <= 1.0:
        raise ProtocolError("out-of-range", "e_omega not in [0, 1]")
    return AgentState(
        _int(body, "agent", 0, limits.agents - 1),
        _int(body, "step", -1, MAX_STEP),
        (pose[0], pose[1], pose[2]),
        vel[0],
        vel[1],
        e_omega,
        (nxt[0], nxt[1], nxt[2]),
        _int(body, "safety", 0, 255) if "safety" in body else 0,
        _finite(body["stamp"], "stamp") if "stamp" in body else 0.0,
    )


def _submap(body: dict[str, Any], key: str) -> dict[str, Any]:
    value = body.get(key)
    if not isinstance(value, dict):
        raise ProtocolError("bad-field", f"{key} must be a map")
    return value


def _submaps(body: dict[str, Any], key: str, most: int) -> list[dict[str, Any]]:
    value = body.get(key, [])
    if not isinstance(value, list) or len(value) > most or not all(isinstance(item, dict) for item in value):
        raise ProtocolError("bad-field", f"{key} must be a list of maps, at most one per agent")
    return value


def _decode_objectives(body: dict[str, Any], limits: Limits) -> Objectives:
    last_agent = limits.agents - 1
    step = _int(body, "step", 0, MAX_STEP)
    members = _members(body, last_agent)
    targets = _floats(body, "targets", 2 * len(members))
    blobs = _floats(body, "blobs")
    if len(blobs) % 2:
        raise ProtocolError("bad-shape", "blobs must hold (x, y) pairs")
    labels = None
    if body.get("labels") is not None:
        raw = _inflate(body["labels"], 2 * limits.rows * limits.cols, "labels")
        labels = np.frombuffer(raw, dtype="<u2").reshape(limits.rows, limits.cols).astype(np.uint16)
        if labels.max(initial=0) > len(blobs) // 2:
            raise ProtocolError("out-of-range", "labels name a blob that does not exist")
    return Objectives(step, tuple(members), np.array(targets).reshape(-1, 2), np.array(blobs).reshape(-1, 2), labels)


def _decode_step(body: dict[str, Any], limits: Limits) -> AgentStep:
    delta = _decode_delta(_submap(body, "delta"), limits)
    state = _decode_state(_submap(body, "state"), limits)
    if delta.agent != state.agent or delta.seq != state.step:
        raise ProtocolError("out-of-range", "a step's delta and state must be of one agent and one step")
    return AgentStep(delta, state)


def _decode_go(body: dict[str, Any], limits: Limits) -> StepGo:
    step = _int(body, "step", 0, MAX_STEP)
    members = _members(body, limits.agents - 1)
    deltas = [_decode_delta(item, limits) for item in _submaps(body, "deltas", limits.agents)]
    states = [_decode_state(item, limits) for item in _submaps(body, "states", limits.agents)]
    if any(delta.seq != step - 1 for delta in deltas) or any(state.step != step - 1 for state in states):
        raise ProtocolError("out-of-range", "a go for step k carries deltas and states of step k-1 only")
    if len({delta.agent for delta in deltas}) != len(deltas) or len({s.agent for s in states}) != len(states):
        raise ProtocolError("out-of-range", "one delta and one state per agent")
    raw_objectives = body.get("objectives")
    if raw_objectives is not None and not isinstance(raw_objectives, dict):
        raise ProtocolError("bad-field", "objectives must be a map or nil")
    objectives = None if raw_objectives is None else _decode_objectives(raw_objectives, limits)
    return StepGo(step, tuple(members), tuple(deltas), objectives, tuple(states))


def _decode_control(body: dict[str, Any], limits: Limits) -> RunControl:
    control_kind = body.get("kind")
    if control_kind not in RUN_CONTROL_KINDS:
        raise ProtocolError("bad-field", f"kind must be one of {RUN_CONTROL_KINDS}")
    completed = body.get("completed")
    reason = body.get("reason")
    if not isinstance(completed, bool) or not isinstance(reason, str) or len(reason) > 1000:
        raise ProtocolError("bad-field", "completed must be a bool and reason a short string")
    return RunControl(control_kind, _int(body, "step", 0, MAX_STEP), completed, _finite(body.get("e_d"), "e_d"), reason)


def _applied(body: dict[str, Any], last_agent: int) -> dict[int, tuple[int, tuple[int, ...]]]:
    """A snapshot's applied sequences: per agent, the contiguous sequence and the extras after it."""
    applied_raw = body.get("applied")
    if not isinstance(applied_raw, list):
        raise ProtocolError("bad-field", "applied must be a list")
    applied: dict[int, tuple[int, tuple[int, ...]]] = {}
    for entry in applied_raw:
        if not (isinstance(entry, list) and len(entry) == 3 and isinstance(entry[2], list)):
            raise ProtocolError("bad-shape", "applied entries are [agent, seq, extras]")
        agent = _int({"a": entry[0]}, "a", 0, last_agent)
        seq = _int({"s": entry[1]}, "s", -1, MAX_STEP)
        extras = tuple(_int({"e": item}, "e", seq + 1, MAX_STEP) for item in entry[2])
        applied[agent] = (seq, extras)
    return applied


def _poses(body: dict[str, Any], last_agent: int) -> dict[int, Pose]:
    """A snapshot's last known pose per agent."""
    poses: dict[int, Pose] = {}
    poses_raw = body.get("poses", [])
    if not isinstance(poses_raw, list):
        raise ProtocolError("bad-field", "poses must be a list")
    for entry in poses_raw:
        if not (isinstance(entry, list) and len(entry) == 4):
            raise ProtocolError("bad-shape", "pose entries are [agent, x, y, theta]")
        agent = _int({"a": entry[0]}, "a", 0, last_agent)
        x, y, theta = (_finite(value, "pose") for value in entry[1:])
        poses[agent] = (x, y, theta)
    return poses


def _decode_snapshot(body: dict[str, Any], limits: Limits) -> Snapshot:
    rows = _int(body, "rows", limits.rows, limits.rows)
    cols = _int(body, "cols", limits.cols, limits.cols)
    raw = _inflate(body.get("map"), 8 * rows * cols, "map")
    coverage = np.frombuffer(raw, dtype="<i8").reshape(rows, cols).astype(np.int64)
    if (coverage < 0).any():
        raise ProtocolError("negative-delta", "map cells must be non-negative")
    applied = _applied(body, limits.agents - 1)
    return Snapshot(coverage, applied, _poses(body, limits.agents - 1))


def _decode_digest(body: dict[str, Any], limits: Limits) -> ScenarioDigest:
    scenario, map_sha = body.get("scenario"), body.get("map")
    for name, value, lengths in (("scenario", scenario, (64,)), ("map", map_sha, (0, 64))):
        if not isinstance(value, str) or len(value) not in lengths or any(c not in "0123456789abcdef" for c in value):
            raise ProtocolError("bad-field", f"{name} must be a sha256 in hex")
    return ScenarioDigest(scenario, map_sha)


MAX_BYTES_COUNTED = 2**62
"""Byte counters above this are refused (a process would need decades at any link's speed)."""


def _decode_traffic(body: dict[str, Any], limits: Limits) -> Traffic:
    role = body.get("role")
    if role not in TRAFFIC_ROLES:
        raise ProtocolError("bad-field", f"role must be one of {TRAFFIC_ROLES}")
    ident = _int(body, "ident", 0, limits.agents - 1 if role == "agent" else 0)
    seconds = _finite(body.get("seconds"), "seconds")
    if seconds < 0.0:
        raise ProtocolError("bad-field", "seconds must be >= 0")
    return Traffic(
        role, ident, seconds, _int(body, "out", 0, MAX_BYTES_COUNTED), _int(body, "in", 0, MAX_BYTES_COUNTED)
    )


_DECODERS: dict[str, Callable[[dict[str, Any], Limits], Message]] = {
    "delta": _decode_delta,
    "state": _decode_state,
    "step": _decode_step,
    "objectives": _decode_objectives,
    "go": _decode_go,
    "control": _decode_control,
    "snapshot": _decode_snapshot,
    "scenario": _decode_digest,
    "traffic": _decode_traffic,
}
"""Each message type's decoder: it validates the body and builds the message, or raises ProtocolError."""


def _decode_compact_step(payload: bytes, limits: Limits) -> AgentStep:
    """A compact step (protocol.messages.COMPACT_STEP), checked as the msgpack form is."""
    if len(payload) < COMPACT_HEAD.size:
        raise ProtocolError("bad-shape", "a compact step is too short")
    _, version, what, agent, step, safety, *numbers = COMPACT_HEAD.unpack_from(payload)
    if version != PROTOCOL_VERSION:
        raise ProtocolError("bad-version", f"expected {PROTOCOL_VERSION}, got {version!r}")
    if what & ~(STAMPED | FIXED | NOTHING_SENSED) or (what & FIXED and what & NOTHING_SENSED):
        raise ProtocolError("bad-field", "unknown parts in a compact step")
    offset, stamp, fixes = COMPACT_HEAD.size, 0.0, []
    try:
        if what & STAMPED:
            (ticks,) = COMPACT_STAMP.unpack_from(payload, offset)
            offset += COMPACT_STAMP.size
            now = round(time.time() * STAMP_UNITS)
            # The time with these low bits nearest the receiver's clock (a sender's clock may run ahead).
            stamp = (now + (ticks - now + 2**31) % 2**32 - 2**31) / STAMP_UNITS
        if what & FIXED:
            (count,) = COMPACT_COUNT.unpack_from(payload, offset)
            offset += COMPACT_COUNT.size
            for _ in range(count):
                fixes.extend(COMPACT_FIX.unpack_from(payload, offset))
                offset += COMPACT_FIX.size
    except struct.error:
        raise ProtocolError("bad-shape", "a compact step ends early") from None
    if offset != len(payload):
        raise ProtocolError("bad-shape", "bytes after a compact step")
    names = ("pose", "pose", "pose", "v", "omega", "e_omega", "next", "next", "next")
    x, y, theta, v, omega, e_omega, *after = (_finite(n, name) for n, name in zip(numbers, names, strict=True))
    state_body = {"agent": agent, "step": step, "pose": [x, y, theta], "vel": [v, omega], "e_omega": e_omega}
    state = _decode_state(state_body | {"next": after, "safety": safety, "stamp": stamp}, limits)
    if what & NOTHING_SENSED:
        return AgentStep(MapDelta(state.agent, step, 0, 0, np.zeros((0, 0), dtype=np.int64)), state)
    return AgentStep(_decode_event({"ev": [x, y, theta], "fix": fixes}, limits, state.agent, step), state)


def decode(payload: bytes, limits: Limits, expected: str | None = None) -> Message:
    """Decode and validate one payload; raise ProtocolError (with ``.reason``) if it is not acceptable."""
    if isinstance(payload, bytes | bytearray | memoryview) and payload[:1] == bytes([COMPACT_STEP]):
        if expected is not None and expected != "step":
            raise ProtocolError("wrong-type", f"expected {expected}, got 'step'")
        return _decode_compact_step(bytes(payload), limits)
    body = _header(payload)
    kind = body.get("type")
    if expected is not None and kind != expected:
        raise ProtocolError("wrong-type", f"expected {expected}, got {kind!r}")
    decoder = _DECODERS.get(kind) if isinstance(kind, str) else None
    if decoder is None:
        raise ProtocolError("unknown-type", repr(kind)[:40])
    return decoder(body, limits)
