"""model.lane_planner: the anicov controller's spiral, its pieces, the carrots and the passes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from model.control import pursuit_law
from model.lane_planner import (
    LOOKAHEAD,
    LanePlanner,
    Route,
    assign_pieces,
    best_lane_spacing,
    blob_passes,
    lead_in,
    spiral_path,
    spiral_pieces,
)
from model.metrics import coverage_distance, straight_pass_coverage
from model.scenario import Scenario, ScenarioError

PAPER = Scenario()


def test_the_best_spacing_is_where_two_full_speed_passes_just_bring_the_midpoint_to_lambda_star():
    spacing = best_lane_spacing(PAPER)
    midway = straight_pass_coverage(spacing / 2.0, PAPER.range, PAPER.half_angle, PAPER.alpha_max)
    assert 2.0 * midway == pytest.approx(PAPER.lambda_star, rel=1e-4)
    d50 = coverage_distance(PAPER.lambda_star / 2.0, PAPER.range, PAPER.half_angle, PAPER.alpha_max)
    assert spacing == pytest.approx(2.0 * d50, rel=1e-4)  # 7.73 on the paper's sensor (Fig. 7)
    # A slower sensor profile moves it: with Λ* doubled full speed no longer reaches it at 2·d50.
    assert best_lane_spacing(PAPER.with_overrides(lambda_star=200.0)) < spacing


def test_the_spiral_stays_inside_its_rings_apart_and_its_pieces_share_it_equally():
    spacing = best_lane_spacing(PAPER)
    path = spiral_path(PAPER, spacing)
    d100 = coverage_distance(PAPER.lambda_star, PAPER.range, PAPER.half_angle, PAPER.alpha_max)
    assert path.min() >= d100 - 1e-9 and path.max() <= 100.0 - d100 + 1e-9
    assert np.allclose(path[1], (100.0 - d100, d100))  # the outer ring first, along the bottom edge
    steps = np.diff(path, axis=0)
    assert np.all((np.abs(steps[:, 0]) < 1e-9) | (np.abs(steps[:, 1]) < 1e-9))  # axis-aligned runs only
    whole = Route.of(path).length
    for agents in (1, 4, 7):
        pieces = spiral_pieces(PAPER.with_overrides(agents=agents), spacing)
        lengths = [Route.of(piece).length for piece in pieces]
        assert len(pieces) == agents and lengths == pytest.approx([whole / agents] * agents)


def test_each_robot_gets_one_piece_from_its_nearer_end_with_a_run_up():
    scenario = PAPER.with_overrides(agents=3)
    pieces = spiral_pieces(scenario, best_lane_spacing(scenario))
    starts = np.array([pieces[2][0] + [1.0, 0.0], pieces[0][-1] + [0.0, 1.0], pieces[1][0]])
    routes = assign_pieces(pieces, starts, lead=5.0)
    assert np.allclose(routes[0][0], starts[0]) and np.allclose(routes[0][-1], pieces[2][-1])  # forward
    assert np.allclose(routes[1][-1], pieces[0][0])  # flown backward, from the end it started by
    run_up = routes[2][2] - routes[2][1]  # the entry point, 5 before the piece's first point along it
    assert np.linalg.norm(run_up) == pytest.approx(5.0) and np.allclose(routes[2][2], pieces[1][0])


def test_progress_follows_the_robot_along_its_route_never_back_and_never_onto_the_next_ring():
    route = Route.of(np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 8.0], [0.0, 8.0]]))
    route.advance(np.array([4.0, 0.5]), window=5.0)
    assert route.progress == pytest.approx(4.0)
    route.advance(np.array([2.0, 0.0]), window=5.0)  # behind: progress stays
    assert route.progress == pytest.approx(4.0)
    route.advance(np.array([4.0, 7.5]), window=5.0)  # close to the ring above, but far ahead along it
    assert route.progress <= 9.0 + 1e-9
    assert np.allclose(route.point_at(route.length + 3.0), [0.0, 8.0])


def test_a_blob_is_passed_along_its_major_axis_and_scraps_along_an_edge_make_one_pass():
    lack = np.zeros((40, 40))
    lack[5:35, 2:4] = 1.0  # a thin strip along x = 2..4
    for row in (10, 20, 30):
        lack[row, 5] = 0.0
    lack[5:35:6, 4] = 0.5  # scraps next to it, within a spacing
    ways, centres, labels = blob_passes(lack, 1.0, lead=3.0, spacing=7.7)
    assert len(ways) == 1 and labels.max() == 1
    entry, exit_ = ways[0][0]
    assert abs(entry[0] - exit_[0]) < 1.0 and abs(entry[1] - exit_[1]) > 30.0  # along the strip, in y
    rows, cols = np.nonzero(lack > 0)
    assert centres[0] == pytest.approx((cols.mean() + 0.5, rows.mean() + 0.5))


def test_carrots_lead_each_robot_along_its_route_and_a_robot_with_nothing_left_stays():
    scenario = PAPER.with_overrides(agents=2, domain=[40.0, 40.0])
    planner = LanePlanner(scenario)
    positions = np.array([[5.0, 5.0], [35.0, 30.0]])
    lack = np.ones(scenario.grid_shape)
    targets = planner.plan(lack, positions)
    for agent in (0, 1):
        route = planner.routes[agent]
        assert np.allclose(targets[agent], route.point_at(route.progress + LOOKAHEAD))
    covered = np.zeros(scenario.grid_shape)
    for route in planner.routes.values():
        route.progress = route.length  # both at the end of their piece, nothing uncovered
    targets = planner.plan(covered, positions)
    assert np.allclose(targets, positions)


@settings(max_examples=300)
@given(st.floats(-50, 50), st.floats(-50, 50), st.floats(-math.pi, math.pi), st.floats(-50, 50), st.floats(-50, 50))
def test_the_pursuit_law_keeps_the_papers_velocity_bounds(x, y, theta, goal_x, goal_y):
    v, omega = pursuit_law(x, y, theta, goal_x, goal_y, 1.0, 1.0, 0.1)
    assert abs(v) <= 1.0 and abs(omega) <= math.pi + 1e-12  # eq. 15-16: |v| ≤ k_v, |ω| ≤ π k_ω


def test_best_names_the_anicov_controller_which_knows_no_walls_and_plans_centrally():
    assert PAPER.with_overrides(controller="best").controller == "anicov"
    assert PAPER.with_overrides(controller="anicov").plan_steps == 5  # a carrot every 0.5 time units
    with pytest.raises(ScenarioError, match="'controller': 'anicov' flies the open domain's lanes"):
        PAPER.with_overrides(controller="anicov", robot_radius=0.5)
    with pytest.raises(ScenarioError, match="'planning'"):
        PAPER.with_overrides(controller="anicov", planning="local")


def test_lead_in_is_where_a_point_half_a_spacing_aside_enters_the_wedge():
    spacing = best_lane_spacing(PAPER)
    assert lead_in(PAPER, spacing) == pytest.approx(spacing / 2.0 / math.tan(PAPER.half_angle))
