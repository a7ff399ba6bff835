"""Message types of the team protocol, encoded with msgpack, versioned and validated.

Every payload is a msgpack map ``{"v": PROTOCOL_VERSION, "type": ..., ...}``.
Encoding (here) never fails for a well-formed value; decoding
(:mod:`protocol.decoding`) checks everything a receiver relies on and raises
:class:`ProtocolError` with a short reason otherwise. Nothing that fails to
decode may touch a map or a controller.

    MapDelta    agent, seq (= step), window (row0, col0, ticks int64 h×w)   eq. 3
                on the wire as cells (the window's ticks) or as a sensing event (the pose the step sensed
                from and the cells whose ticks the integer kernel rounds otherwise): protocol.events
    AgentState  agent, step, pose at t_k, v, ω, e_Ω, pose at t_k+1 (step −1: hello), safety filter flags
    AgentStep   what an agent publishes each step: its MapDelta and its AgentState; with its delta as
                an event it travels in the compact binary form below (82 bytes; 86 realtime; fixes 2 + 12 each)
    StepGo      lockstep: step k may start; every member's step k−1 delta and state
    Objectives  step k, members, targets (one per member), blob objectives  Alg. 1–2
    RunControl  kind (done | abort | status), step, completed, e_D, reason
    Snapshot    the coverage map and the applied sequences per agent
    ScenarioDigest  sha256 of the scenario as run and of its map (a process checks it joins its team's run)
    Traffic     a process's bytes out and in since it started, every second (bandwidth you can see)
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass, field
from typing import Any

import msgpack
import numpy as np

from model.parameters import exact_kernel_of
from model.radio.exact_coverage import ExactKernel
from model.scenario import Scenario

PROTOCOL_VERSION = 1
MAX_PAYLOAD_BYTES = 8 * 1024 * 1024
"""Larger payloads are rejected before decoding (a snapshot of a 1000×1000 map compresses far below)."""


Pose = tuple[float, float, float]


class ProtocolError(ValueError):
    """A payload that cannot be accepted; ``reason`` is a short, countable label."""

    def __init__(self, reason: str, detail: str = "") -> None:
        super().__init__(f"{reason}: {detail}" if detail else reason)
        self.reason = reason


@dataclass(frozen=True)
class Limits:
    """What a receiver accepts: the grid it holds and the team size; and the integer coverage kernel
    that turns a delta sent as a sensing event into ticks (None: events are refused)."""

    rows: int
    cols: int
    agents: int
    kernel: ExactKernel | None = None

    @classmethod
    def of(cls, scenario: Scenario) -> Limits:
        """The limits of a scenario's team: its grid, its size and its sensor's integer kernel."""
        return cls(*scenario.grid_shape, scenario.agents, exact_kernel_of(scenario))


Pose = tuple[float, float, float]


@dataclass(frozen=True)
class SensingEvent:
    """The cause of a delta (issue 13): the pose a step sensed from, and the cells (flat index in the
    integer kernel's window, ticks) where the sender's ticks differ from that kernel's."""

    pose: Pose
    fixes: tuple[tuple[int, int], ...] = ()


@dataclass(frozen=True)
class MapDelta:
    agent: int
    seq: int
    row0: int
    col0: int
    ticks: np.ndarray  # int64 (h, w), non-negative
    event: SensingEvent | None = None  # set: it travels as this event (protocol.events), not as cells


@dataclass(frozen=True)
class AgentState:
    agent: int
    step: int  # -1: hello, the pose at t_0 in next_pose
    pose: Pose
    v: float
    omega: float
    e_omega: float
    next_pose: Pose
    safety: int = 0  # what the safety filter did this step (model.safety.safety flag bits; 0: nothing)
    stamp: float = 0.0  # realtime: the wall-clock time (time.time(), s) it reached next_pose; 0 in lockstep


@dataclass(frozen=True)
class Objectives:
    step: int
    members: tuple[int, ...]
    targets: np.ndarray  # (len(members), 2): target of members[i]
    blobs: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # Ψ of Alg. 1
    labels: np.ndarray | None = None  # uint16 (rows, cols): blob π_j of each cell, 0 = none (for the logger)

    def target_of(self, agent: int) -> tuple[float, float] | None:
        if agent not in self.members:
            return None
        x, y = self.targets[self.members.index(agent)]
        return float(x), float(y)


RUN_CONTROL_KINDS = ("done", "abort", "status")


@dataclass(frozen=True)
class RunControl:
    kind: str
    step: int
    completed: bool = False
    domain_error: float = 1.0
    reason: str = ""


@dataclass(frozen=True)
class Snapshot:
    coverage: np.ndarray  # int64 (rows, cols)
    applied: dict[int, tuple[int, tuple[int, ...]]]  # agent → (contiguous seq, extra seqs)
    poses: dict[int, Pose] = field(default_factory=dict)  # last known pose per agent (for a restarted robot)


@dataclass(frozen=True)
class AgentStep:
    """One agent's step k: the coverage it added and its state, in one message (one send, one delivery)."""

    delta: MapDelta
    state: AgentState

    @property
    def agent(self) -> int:
        return self.state.agent


@dataclass(frozen=True)
class StepGo:
    """Lockstep: step k may start. Carries every member's step k−1 delta and state (so a listener needs
    no other message), and on a replan the objectives."""

    step: int
    members: tuple[int, ...]
    deltas: tuple[MapDelta, ...]
    objectives: Objectives | None = None
    states: tuple[AgentState, ...] = ()


@dataclass(frozen=True)
class ScenarioDigest:
    """What the coordinator runs: sha256 (hex) of the scenario's keys, and of its map files ('' if none)."""

    scenario: str
    map_sha256: str


TRAFFIC_ROLES = ("agent", "coordinator", "logger")


@dataclass(frozen=True)
class Traffic:
    """What one process has put on the bus and taken from it since it started (payload bytes, counters
    that only grow), ``seconds`` after its start: a listener turns two reports into bytes per second."""

    role: str
    ident: int
    seconds: float
    bytes_out: int
    bytes_in: int


Message = MapDelta | AgentState | AgentStep | Objectives | RunControl | Snapshot | StepGo | ScenarioDigest | Traffic


# ---------------------------------------------------------------- encoding


def _pack(kind: str, body: dict[str, Any]) -> bytes:
    return msgpack.packb({"v": PROTOCOL_VERSION, "type": kind, **body}, use_bin_type=True)


def _delta_body(message: MapDelta) -> dict[str, Any]:
    if message.event is not None:
        fixes = [number for fix in message.event.fixes for number in fix]
        return {"agent": message.agent, "seq": message.seq, "ev": list(message.event.pose), "fix": fixes}
    ticks = np.ascontiguousarray(message.ticks, dtype="<i8")
    return {
        "agent": message.agent,
        "seq": message.seq,
        "row0": message.row0,
        "col0": message.col0,
        "h": ticks.shape[0],
        "w": ticks.shape[1],
        "ticks": ticks.tobytes(),
    }


def _state_body(message: AgentState) -> dict[str, Any]:
    return (
        {
            "agent": message.agent,
            "step": message.step,
            "pose": list(message.pose),
            "vel": [message.v, message.omega],
            "e_omega": message.e_omega,
            "next": list(message.next_pose),
        }
        | ({"safety": message.safety} if message.safety else {})
        | ({"stamp": message.stamp} if message.stamp else {})
    )


def _objectives_body(message: Objectives) -> dict[str, Any]:
    body: dict[str, Any] = {
        "step": message.step,
        "members": list(message.members),
        "targets": np.asarray(message.targets, float).ravel().tolist(),
        "blobs": np.asarray(message.blobs, float).ravel().tolist(),
    }
    if message.labels is not None:
        body["labels"] = zlib.compress(np.ascontiguousarray(message.labels, dtype="<u2").tobytes(), 1)
    return body


COMPACT_STEP = 0xC1
"""First byte of a compact step: a byte msgpack never uses, so no msgpack payload starts with it.

The compact step (issue 13: at most 100 bytes on the bus per agent-step), little-endian:

    B 0xC1 · B PROTOCOL_VERSION · B what follows (1: a stamp, 2: fixes, 4: nothing sensed) ·
    H agent · I step · B safety flags · 9 float64: pose x, y, θ, v, ω, e_Ω, next pose x, y, θ ·
    [I stamp: wall-clock time in 100 µs units modulo 2³², unwrapped by the receiver to the nearest time] ·
    [H count · count × (I index, Q ticks): the event's fixes]

The delta is the sensing event from ``pose`` (protocol.events), or nothing sensed (a held step).
"""
COMPACT_HEAD = struct.Struct("<BBBHIB9d")
COMPACT_STAMP = struct.Struct("<I")
COMPACT_COUNT = struct.Struct("<H")
COMPACT_FIX = struct.Struct("<IQ")
STAMP_UNITS = 10_000  # per second
STAMPED, FIXED, NOTHING_SENSED = 1, 2, 4


def compact_step(message: AgentStep) -> bytes | None:
    """The compact binary form of a step whose delta is an event or empty; None when it does not fit."""
    delta, state = message.delta, message.state
    sensed_nothing = delta.event is None and delta.ticks.size == 0
    if (delta.event is None and not sensed_nothing) or not 0 <= state.step < 2**32:
        return None
    if delta.event is not None and (delta.event.pose != state.pose or len(delta.event.fixes) >= 2**16):
        return None
    fixes = delta.event.fixes if delta.event is not None else ()
    what = (STAMPED if state.stamp else 0) | (FIXED if fixes else 0) | (NOTHING_SENSED if sensed_nothing else 0)
    numbers = (*state.pose, state.v, state.omega, state.e_omega, *state.next_pose)
    parts = [COMPACT_HEAD.pack(COMPACT_STEP, PROTOCOL_VERSION, what, state.agent, state.step, state.safety, *numbers)]
    if state.stamp:
        parts.append(COMPACT_STAMP.pack(round(state.stamp * STAMP_UNITS) % 2**32))
    if fixes:
        parts.append(COMPACT_COUNT.pack(len(fixes)))
        parts.extend(COMPACT_FIX.pack(index, ticks) for index, ticks in fixes)
    return b"".join(parts)


def encode(message: Message) -> bytes:
    if isinstance(message, AgentStep) and (compact := compact_step(message)) is not None:
        return compact
    if isinstance(message, MapDelta):
        return _pack("delta", _delta_body(message))
    if isinstance(message, StepGo):
        return _pack(
            "go",
            {
                "step": message.step,
                "members": list(message.members),
                "deltas": [_delta_body(delta) for delta in message.deltas],
                "states": [_state_body(state) for state in message.states],
                "objectives": None if message.objectives is None else _objectives_body(message.objectives),
            },
        )
    if isinstance(message, AgentStep):
        return _pack("step", {"delta": _delta_body(message.delta), "state": _state_body(message.state)})
    if isinstance(message, AgentState):
        return _pack("state", _state_body(message))
    if isinstance(message, Objectives):
        return _pack("objectives", _objectives_body(message))
    if isinstance(message, RunControl):
        return _pack(
            "control",
            {
                "kind": message.kind,
                "step": message.step,
                "completed": message.completed,
                "e_d": message.domain_error,
                "reason": message.reason,
            },
        )
    if isinstance(message, Snapshot):
        coverage = np.ascontiguousarray(message.coverage, dtype="<i8")
        applied = [[agent, seq, list(extra)] for agent, (seq, extra) in sorted(message.applied.items())]
        return _pack(
            "snapshot",
            {
                "rows": coverage.shape[0],
                "cols": coverage.shape[1],
                "map": zlib.compress(coverage.tobytes(), 1),
                "applied": applied,
                "poses": [[agent, *pose] for agent, pose in sorted(message.poses.items())],
            },
        )
    if isinstance(message, ScenarioDigest):
        return _pack("scenario", {"scenario": message.scenario, "map": message.map_sha256})
    if isinstance(message, Traffic):
        return _pack(
            "traffic",
            {
                "role": message.role,
                "ident": message.ident,
                "seconds": message.seconds,
                "out": message.bytes_out,
                "in": message.bytes_in,
            },
        )
    raise TypeError(f"not a protocol message: {type(message).__name__}")
