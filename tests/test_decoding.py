"""protocol.decoding: what is not a valid message is rejected with a short, countable reason."""

import math

import msgpack
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from protocol.decoding import decode
from protocol.messages import (
    PROTOCOL_VERSION,
    AgentState,
    AgentStep,
    Limits,
    MapDelta,
    ProtocolError,
    StepGo,
    encode,
)

LIMITS = Limits(rows=100, cols=100, agents=4)


def reason_of(payload: bytes, expected: str | None = None) -> str:
    with pytest.raises(ProtocolError) as caught:
        decode(payload, LIMITS, expected)
    return caught.value.reason


def test_a_step_whose_delta_and_state_disagree_is_rejected():
    state = AgentState(2, 9, (1.0, 2.0, 0.5), 0.25, -0.5, 0.75, (1.1, 2.1, 0.55))
    other_agent = encode(AgentStep(MapDelta(1, 9, 4, 5, np.ones((1, 1), np.int64)), state))
    other_step = encode(AgentStep(MapDelta(2, 8, 4, 5, np.ones((1, 1), np.int64)), state))
    assert reason_of(other_agent) == reason_of(other_step) == "out-of-range"
    stale = encode(StepGo(10, (2,), (), None, (state,)))  # a state of step 9 belongs to the go of step 10 ...
    assert decode(stale, LIMITS).states == (state,)
    assert reason_of(encode(StepGo(11, (2,), (), None, (state,)))) == "out-of-range"  # ... not of step 11
    twice = encode(StepGo(10, (2,), (), None, (state, state)))
    assert reason_of(twice) == "out-of-range"


def body(**fields):
    return msgpack.packb({"v": PROTOCOL_VERSION, **fields}, use_bin_type=True)


def good_delta(**changes):
    fields = {
        "type": "delta",
        "agent": 1,
        "seq": 3,
        "row0": 10,
        "col0": 10,
        "h": 2,
        "w": 2,
        "ticks": np.ones(4, "<i8").tobytes(),
    }
    fields.update(changes)
    return body(**fields)


@pytest.mark.parametrize(
    ("payload", "reason"),
    [
        (b"", "undecodable"),
        (b"\xc1garbage", "bad-shape"),  # 0xC1 opens a compact step: too short for one
        (b"\xc0\xc1", "undecodable"),  # msgpack nil, then a byte msgpack never uses
        (msgpack.packb([1, 2, 3]), "not-a-map"),
        (msgpack.packb({"v": 99, "type": "delta"}), "bad-version"),
        (body(type="teleport"), "unknown-type"),
        (good_delta(agent=4), "out-of-range"),
        (good_delta(agent=-1), "out-of-range"),
        (good_delta(agent=True), "bad-field"),
        (good_delta(row0=99), "window-outside-grid"),
        (good_delta(ticks=b"\x00" * 8), "bad-shape"),
        (good_delta(ticks=np.array([1, -1, 1, 1], "<i8").tobytes()), "negative-delta"),
        (
            body(type="state", agent=0, step=1, pose=[0.0, math.nan, 0.0], vel=[0, 0], e_omega=0.5, next=[0, 0, 0]),
            "not-finite",
        ),
        (body(type="state", agent=0, step=1, pose=[0.0, 0.0], vel=[0, 0], e_omega=0.5, next=[0, 0, 0]), "bad-shape"),
        (body(type="state", agent=0, step=1, pose=[0, 0, 0], vel=[0, 0], e_omega=1.5, next=[0, 0, 0]), "out-of-range"),
        (body(type="objectives", step=1, members=[0, 0], targets=[0, 0, 0, 0], blobs=[]), "out-of-range"),
        (body(type="objectives", step=1, members=[0], targets=[0], blobs=[]), "bad-shape"),
        (body(type="step", delta=[1, 2], state={}), "bad-field"),
        (body(type="go", step=3, members=[0], deltas=[], states=[1]), "bad-field"),
        (body(type="control", kind="explode", step=1, completed=False, e_d=0.0, reason=""), "bad-field"),
        (body(type="snapshot", rows=100, cols=100, map=b"not zlib", applied=[]), "undecodable"),
        (body(type="snapshot", rows=50, cols=100, map=b"", applied=[]), "out-of-range"),
        (body(type="traffic", role="router", ident=0, seconds=1.0, out=0, **{"in": 0}), "bad-field"),
        (body(type="traffic", role="agent", ident=4, seconds=1.0, out=0, **{"in": 0}), "out-of-range"),
        (body(type="traffic", role="coordinator", ident=1, seconds=1.0, out=0, **{"in": 0}), "out-of-range"),
        (body(type="traffic", role="agent", ident=0, seconds=-1.0, out=0, **{"in": 0}), "bad-field"),
        (body(type="traffic", role="agent", ident=0, seconds=1.0, out=-5, **{"in": 0}), "out-of-range"),
        (body(type="traffic", role="agent", ident=0, seconds=math.inf, out=0, **{"in": 0}), "not-finite"),
    ],
)
def test_malformed_payloads_are_rejected_with_a_reason(payload, reason):
    assert reason_of(payload) == reason


def test_wrong_type_where_one_is_expected():
    assert reason_of(good_delta(), expected="snapshot") == "wrong-type"


def test_oversized_payload_is_rejected_before_decoding():
    assert reason_of(b"\x00" * (9 * 1024 * 1024)) == "too-large"


@settings(max_examples=300)
@given(st.binary(max_size=300))
def test_random_bytes_never_escape_as_other_exceptions(payload):
    try:
        decode(payload, LIMITS)
    except ProtocolError:
        pass


@settings(max_examples=300)
@given(st.integers(0, 200), st.integers(0, 255))
def test_mutated_delta_is_either_valid_or_rejected(position, value):
    payload = bytearray(good_delta())
    payload[position % len(payload)] = value
    try:
        message = decode(bytes(payload), LIMITS)
    except ProtocolError:
        return
    if isinstance(message, MapDelta):
        assert (message.ticks >= 0).all()
        assert message.row0 + message.ticks.shape[0] <= 100 and message.col0 + message.ticks.shape[1] <= 100


def test_a_malformed_compact_step_is_rejected():
    import struct

    from model.scenario import PAPER_SCENARIO, load_scenario
    from protocol.messages import COMPACT_HEAD

    limits = Limits.of(load_scenario(PAPER_SCENARIO))
    numbers = (50.0, 50.0, 0.5, 0.5, 0.1, 0.2, 50.1, 50.0, 0.51)

    def compact(*, version=PROTOCOL_VERSION, what=0, agent=1, step=4, safety=0, floats=numbers, tail=b""):
        return COMPACT_HEAD.pack(0xC1, version, what, agent, step, safety, *floats) + tail

    def reason(payload: bytes) -> str:
        with pytest.raises(ProtocolError) as caught:
            decode(payload, limits)
        return caught.value.reason

    assert decode(compact(), limits).state.step == 4
    assert reason(compact()[:-1]) == "bad-shape"
    assert reason(compact(tail=b"x")) == "bad-shape"
    assert reason(compact(version=9)) == "bad-version"
    assert reason(compact(what=8)) == reason(compact(what=6)) == "bad-field"
    assert reason(compact(what=2, tail=struct.pack("<H", 1))) == "bad-shape"  # one fix announced, none there
    assert reason(compact(agent=4)) == "out-of-range"
    assert reason(compact(floats=(*numbers[:5], 1.5, *numbers[6:]))) == "out-of-range"  # e_Ω > 1
    assert reason(compact(floats=(math.nan, *numbers[1:]))) == "not-finite"
    assert reason(compact(what=2, tail=struct.pack("<HIQ", 1, 10**6, 1))) == "out-of-range"  # past the window
    with pytest.raises(ProtocolError) as caught:
        decode(compact(), limits, expected="go")
    assert caught.value.reason == "wrong-type"
