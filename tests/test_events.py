"""protocol.events: a delta sent as its sensing event arrives as exactly the sender's ticks; what is not
a valid event is rejected before anything is computed from it."""

from __future__ import annotations

import math

import msgpack
import numpy as np
import pytest

from model.controllers import law_parameters
from model.parameters import coverage_map_of
from model.scenario import PAPER_SCENARIO, load_scenario
from model.step import read_wedge
from model.world.occlusion import teammates_in_view
from model.world.world import world_of
from protocol.decoding import decode
from protocol.events import as_event
from protocol.messages import PROTOCOL_VERSION, AgentState, AgentStep, Limits, MapDelta, ProtocolError, StepGo, encode

PAPER = load_scenario(PAPER_SCENARIO)


def placed(delta: MapDelta, shape: tuple[int, int]) -> np.ndarray:
    grid = np.zeros(shape, np.int64)
    grid[delta.row0 : delta.row0 + delta.ticks.shape[0], delta.col0 : delta.col0 + delta.ticks.shape[1]] = delta.ticks
    return grid


def sensed_deltas(scenario, count: int, seed: int):
    """(pose, the float kernel's delta) of seeded poses, teammates about (they hide cells on a terrain)."""
    grid = coverage_map_of(scenario)
    law, ground = law_parameters(scenario, grid), world_of(scenario).ground
    rng = np.random.default_rng(seed)
    width, height = scenario.domain
    for step in range(count):
        pose = (rng.uniform(0, width), rng.uniform(0, height), rng.uniform(-math.pi, math.pi))
        positions = np.array([pose[:2], (pose[0] + rng.uniform(-6, 6), pose[1] + rng.uniform(-6, 6))])
        teammates = teammates_in_view(ground, positions, 0, pose[0], pose[1], law.sensing_range)
        *_, row0, col0, ticks = read_wedge(grid.coverage, *pose, law, ground, teammates)
        yield pose, MapDelta(1, step, row0, col0, ticks)


@pytest.mark.parametrize("name", ["paper", "office", "field"])
def test_an_event_arrives_as_exactly_the_senders_ticks(name):
    """On the maps, with occlusion, the cells a wall or a teammate hid travel as fixes."""
    scenario = load_scenario(PAPER_SCENARIO.parent / f"{name}.toml").with_overrides(agents=2, robot_radius=0.5)
    limits = Limits.of(scenario)
    events = 0
    for pose, delta in sensed_deltas(scenario, 300, seed=4):
        sent = as_event(delta, pose, limits.kernel)
        events += sent.event is not None
        payload = encode(AgentStep(sent, AgentState(1, delta.seq, pose, 0.5, 0.1, 0.2, pose)))
        arrived = decode(payload, limits).delta
        assert (placed(arrived, scenario.grid_shape) == placed(delta, scenario.grid_shape)).all()
        if sent.event is not None:
            assert len(encode(sent)) < len(encode(delta))
    assert events >= 250  # the rest sensed nothing on the grid (cells form, empty)


def test_on_the_papers_sensor_an_event_is_a_few_dozen_bytes():
    limits = Limits.of(PAPER)
    sizes = [len(encode(as_event(delta, pose, limits.kernel))) for pose, delta in sensed_deltas(PAPER, 200, seed=8)]
    cells = [len(encode(delta)) for _, delta in sensed_deltas(PAPER, 200, seed=8)]
    assert max(sizes) <= 80 and np.mean(cells) > 1500


def test_without_a_kernel_the_delta_stays_cells_and_a_go_carries_events():
    pose, delta = next(sensed_deltas(PAPER, 1, seed=3))
    assert as_event(delta, pose, None) is delta
    limits = Limits.of(PAPER)
    sent = as_event(delta, pose, limits.kernel)
    go = decode(encode(StepGo(1, (1,), (sent,))), limits)
    assert go.deltas[0].event == sent.event
    assert (placed(go.deltas[0], PAPER.grid_shape) == placed(delta, PAPER.grid_shape)).all()


def event_body(**changes) -> bytes:
    body = {"v": PROTOCOL_VERSION, "type": "delta", "agent": 1, "seq": 4, "ev": [50.0, 50.0, 0.3], "fix": []}
    return msgpack.packb(body | changes, use_bin_type=True)


@pytest.mark.parametrize(
    ("changes", "reason"),
    [
        ({"ev": [50.0, float("nan"), 0.3]}, "not-finite"),
        ({"ev": [50.0, 50.0]}, "bad-shape"),
        ({"ev": [5e7, 50.0, 0.3]}, "out-of-range"),
        ({"fix": [3]}, "bad-shape"),
        ({"fix": [5, 10, 5, 11]}, "out-of-range"),  # indices must increase
        ({"fix": [41 * 41, 1]}, "out-of-range"),  # past the window (41 × 41 cells here)
        ({"fix": [0, -1]}, "out-of-range"),
        ({"fix": [0, 2**41]}, "out-of-range"),
        ({"fix": "x"}, "bad-shape"),
    ],
)
def test_a_malformed_event_is_rejected(changes, reason):
    with pytest.raises(ProtocolError) as caught:
        decode(event_body(**changes), Limits.of(PAPER))
    assert caught.value.reason == reason


def test_a_team_without_a_kernel_refuses_events():
    with pytest.raises(ProtocolError) as caught:
        decode(event_body(), Limits(100, 100, 4))
    assert caught.value.reason == "no-kernel"
    assert decode(event_body(fix=[0, 7]), Limits.of(PAPER)).ticks.reshape(-1)[0] == 7


def test_a_delta_reaching_outside_the_kernels_window_stays_cells():
    """Only a sender whose ticks the kernel cannot place travels as cells (here: a made-up far window)."""
    limits = Limits.of(PAPER)
    pose, delta = next(sensed_deltas(PAPER, 1, seed=3))
    far = MapDelta(1, 0, 90, 90, np.ones((3, 3), np.int64))
    assert as_event(far, (10.0, 10.0, 0.0), limits.kernel) is far
    shifted = MapDelta(1, 0, delta.row0, delta.col0, np.pad(delta.ticks, ((0, 0), (0, 1)), constant_values=1))
    edge = as_event(shifted, pose, limits.kernel)
    assert edge is shifted or (placed(edge, PAPER.grid_shape) == placed(shifted, PAPER.grid_shape)).all()
