import math

import numpy as np
import pytest

from anicov.engine import run_scenario
from model.controllers.zigzag.zigzag import (
    WaypointPilot,
    lane_offsets,
    split_lanes,
    zigzag_start_poses,
    zigzag_waypoints,
)


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


def test_a_path_is_cut_into_stretches_that_join_up():
    from model.paper.polyline import path_between

    path = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 5.0], [0.0, 5.0]])
    first, second = path_between(path, 0.0, 12.5), path_between(path, 12.5, 25.0)
    assert np.allclose(first, [[0, 0], [10, 0], [10, 2.5]]) and np.allclose(second, [[10, 2.5], [10, 5], [0, 5]])


@pytest.mark.parametrize("agents", [1, 3, 7])
def test_the_boustrophedon_team_covers_everything_from_random_starts(paper_scenario, agents):
    """N robots share the one-robot path: every run completes, each robot drives from its own start."""
    scenario = paper_scenario.with_overrides(controller="boustrophedon", agents=agents, domain=(40.0, 30.0), seed=2)
    result = run_scenario(scenario)
    assert result.completed
    lengths = result.path_lengths
    assert lengths.max() < 1.6 * lengths.min() + 40.0  # equal shares, up to the transit and the overlap R


def test_each_robot_gets_the_piece_that_keeps_the_teams_transit_least(paper_scenario):
    from itertools import permutations

    from model.controllers.zigzag.zigzag import boustrophedon_pilots

    scenario = paper_scenario.with_overrides(controller="boustrophedon", agents=3)
    poses = np.array([[90.0, 90.0, 0.0], [5.0, 5.0, 0.0], [50.0, 50.0, 0.0]])
    pilots = boustrophedon_pilots(scenario, poses)
    chosen = sum(np.linalg.norm(pilot.waypoints[0] - poses[i, :2]) for i, pilot in enumerate(pilots))
    starts = [pilot.waypoints[0] for pilot in pilots] + [pilot.waypoints[-1] for pilot in pilots]
    best = min(
        sum(
            min(np.linalg.norm(poses[i, :2] - starts[p]), np.linalg.norm(poses[i, :2] - starts[p + 3]))
            for i, p in enumerate(order)
        )
        for order in permutations(range(3))
    )
    assert chosen <= best + 3 * scenario.range  # a piece's start may lie R back along the path from its cut
    assert np.linalg.norm(pilots[1].waypoints[0] - [-scenario.range, 0.0]) < 30.0  # the corner robot starts near it
