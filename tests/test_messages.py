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
