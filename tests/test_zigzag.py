import math

import numpy as np
import pytest

from anicov.engine import run_scenario
from model.zigzag import WaypointPilot, lane_offsets, split_lanes, zigzag_start_poses, zigzag_waypoints


def test_paper_lanes_fig8():
    lanes = lane_offsets(100.0, 2.72, 2 * 3.865)
    assert len(lanes) == 14
    assert lanes[0] == pytest.approx(2.72) and lanes[-1] == pytest.approx(97.28)


def test_waypoints_alternate_direction_and_lanes_are_140_long():
    points = zigzag_waypoints(100.0, np.array([1.0, 2.0]), 20.0, 0)
    assert points.tolist() == [[-20.0, 1.0], [120.0, 1.0], [120.0, 2.0], [-20.0, 2.0]]


def test_split_lanes_keeps_global_parity():
    blocks = split_lanes(np.arange(14.0), 3)
    assert [first for first, _ in blocks] == [0, 5, 10]
    assert sum(len(block) for _, block in blocks) == 14


def test_pilot_turns_in_place_at_quarter_pi_rate_then_drives():
    pilot = WaypointPilot(np.array([[0.0, 10.0]]), k_v=1.0, turn_rate=math.pi / 2, dt=0.1)
    v, omega = pilot.velocities(0.0, 0.0, 0.0)
    assert v == 0.0 and omega == pytest.approx(math.pi / 2)
    v, omega = pilot.velocities(0.0, 0.0, math.pi / 2)
    assert v == 1.0 and omega == pytest.approx(0.0)


def test_one_agent_zigzag_reproduces_fig8_time_and_path(paper_scenario):
    scenario = paper_scenario.with_overrides(controller="zigzag", agents=1)
    result = run_scenario(scenario, poses=zigzag_start_poses(scenario), record_trace=False)
    assert result.completed
    assert result.path_lengths.sum() == pytest.approx(2054.6, rel=0.01)
    assert result.plan_time == pytest.approx(2080.6, rel=0.01)
    assert result.completion_time <= result.plan_time
