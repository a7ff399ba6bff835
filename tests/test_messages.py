"""protocol.messages: every message type goes on the wire and comes back whole."""

import numpy as np

from protocol.decoding import decode
from protocol.messages import (
    AgentState,
    AgentStep,
    Limits,
    MapDelta,
    Objectives,
    RunControl,
    Snapshot,
    StepGo,
    Traffic,
    encode,
)

LIMITS = Limits(rows=100, cols=100, agents=4)


def test_delta_round_trip():
    ticks = np.arange(12, dtype=np.int64).reshape(3, 4)
    back = decode(encode(MapDelta(2, 17, 5, 6, ticks)), LIMITS)
    assert isinstance(back, MapDelta)
    assert (back.agent, back.seq, back.row0, back.col0) == (2, 17, 5, 6)
    assert np.array_equal(back.ticks, ticks)


def test_state_objectives_control_snapshot_round_trip():
    state = AgentState(1, 4, (1.0, 2.0, 0.5), 0.25, -0.5, 0.75, (1.1, 2.1, 0.55))
    assert decode(encode(state), LIMITS) == state
    objectives = decode(
        encode(Objectives(50, (0, 2), np.array([[1.0, 2.0], [3.0, 4.0]]), np.array([[5.0, 6.0]]))), LIMITS
    )
    assert objectives.members == (0, 2) and objectives.target_of(2) == (3.0, 4.0) and objectives.target_of(1) is None
    control = RunControl("done", 6050, True, 0.0, "")
    assert decode(encode(control), LIMITS) == control
    coverage = np.random.default_rng(1).integers(0, 10**9, (100, 100))
    snapshot = decode(encode(Snapshot(coverage, {0: (5, (7, 9)), 3: (-1, ())})), LIMITS)
    assert np.array_equal(snapshot.coverage, coverage)
    assert snapshot.applied == {0: (5, (7, 9)), 3: (-1, ())}


def test_a_step_and_a_go_carry_deltas_and_states_whole():
    ticks = np.full((2, 3), 7, dtype=np.int64)
    state = AgentState(2, 9, (1.0, 2.0, 0.5), 0.25, -0.5, 0.75, (1.1, 2.1, 0.55))
    step = decode(encode(AgentStep(MapDelta(2, 9, 4, 5, ticks), state)), LIMITS)
    assert isinstance(step, AgentStep) and step.agent == 2 and step.state == state
    assert np.array_equal(step.delta.ticks, ticks) and (step.delta.row0, step.delta.col0) == (4, 5)
    go = decode(encode(StepGo(10, (0, 2), (step.delta,), None, (state,))), LIMITS)
    assert isinstance(go, StepGo) and go.states == (state,) and go.deltas[0].agent == 2


def compact_round_trip(delta: MapDelta, state: AgentState, limits: Limits) -> tuple[bytes, AgentStep]:
    payload = encode(AgentStep(delta, state))
    back = decode(payload, limits)
    assert isinstance(back, AgentStep)
    return payload, back


def test_a_step_with_an_event_travels_compact_and_comes_back_whole():
    """82 bytes in lockstep, 86 realtime (a 100 µs stamp), 2 + 12 per fix; a held step's empty delta too."""
    import time

    from model.scenario import PAPER_SCENARIO, load_scenario
    from protocol.events import delta_of_event
    from protocol.messages import SensingEvent

    limits = Limits.of(load_scenario(PAPER_SCENARIO))
    pose = (40.25, 61.5, -2.75)
    state = AgentState(3, 1234, pose, 0.5, -0.25, 0.125, (40.3, 61.45, -2.8), 17)
    event = delta_of_event(3, 1234, SensingEvent(pose, ((5, 9), (700, 123456789))), limits.kernel)
    payload, back = compact_round_trip(event, state, limits)
    assert payload[0] == 0xC1 and len(payload) == 82 + 2 + 2 * 12
    assert back.state == state and back.delta.event == event.event
    assert np.array_equal(back.delta.ticks, event.ticks) and back.delta.row0 == event.row0
    now = time.time()
    stamped = AgentState(3, 1234, pose, 0.5, -0.25, 0.125, (40.3, 61.45, -2.8), 0, now)
    plain = delta_of_event(3, 1234, SensingEvent(pose), limits.kernel)
    payload, back = compact_round_trip(plain, stamped, limits)
    assert len(payload) == 86 and abs(back.state.stamp - now) <= 1e-4
    ahead = AgentState(3, 1234, pose, 0.5, -0.25, 0.125, (40.3, 61.45, -2.8), 0, now + 2.0)  # its clock runs ahead
    assert abs(compact_round_trip(plain, ahead, limits)[1].state.stamp - (now + 2.0)) <= 1e-4
    held = MapDelta(3, 1234, 0, 0, np.zeros((0, 0), np.int64))
    payload, back = compact_round_trip(held, state, limits)
    assert len(payload) == 82 and back.delta.ticks.shape == (0, 0) and back.delta.event is None


def test_a_traffic_report_round_trips():
    report = Traffic("agent", 3, 12.5, 10_250, 31_000)
    assert decode(encode(report), LIMITS) == report
    assert len(encode(report)) < 80  # one a second: well under 1 % of a robot's traffic
