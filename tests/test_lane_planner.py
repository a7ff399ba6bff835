"""model.controllers.anicov.lane_planner: the anicov controller's carrots along its routes, and the passes over what is left."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from anicov.engine import run_scenario
from model.controllers.anicov.lane_planner import LOOKAHEAD, LanePlanner, blob_passes
from model.paper.control import pursuit_law
from model.paper.geometry import wrap_angle
from model.parameters import starting_poses
from model.scenario import Scenario, ScenarioError, load_scenario

PAPER = Scenario(stations=False)  # the spiral (tests/test_stations.py has the stations)


@pytest.mark.slow  # 20 s of CPU on one of the 2 cores, one seed's regression run: outside the default suite (-m slow),
# which stood at 609 s from a fresh clone on 2026-12-07, over its 10-minute budget
def test_a_team_on_a_long_strip_finishes_its_last_small_blobs():
    """Found on the 200 x 50 strip (R = 10): a one-cell blob left at the end was shuttled over for ever
    when progress took the pass's way back for its way out (N = 2, seed 1: now complete)."""
    scenario = load_scenario(Path(__file__).resolve().parent.parent / "scenarios" / "wide.toml")
    result = run_scenario(scenario.with_overrides(agents=2, seed=1, controller="anicov"), record_trace=False)
    assert result.completed and result.completion_time < 2.0 * 1274.0  # under 2 t*_2 of the strip


def test_a_blob_is_passed_along_its_major_axis_and_scraps_along_an_edge_make_one_pass():
    lack = np.zeros((40, 40))
    lack[5:35, 2:4] = 1.0  # a thin strip along x = 2..4
    for row in (10, 20, 30):
        lack[row, 5] = 0.0
    lack[5:35:6, 4] = 0.5  # scraps next to it, within a spacing
    ways, centres, labels = blob_passes(lack, 1.0, lead=3.0, spacing=7.7)
    assert len(ways) == 1 and labels.max() == 1
    entry, exit_ = ways[0][0]
    assert abs(entry[0] - exit_[0]) < 1.0 and abs(entry[1] - exit_[1]) == pytest.approx(29.0, abs=0.5)  # along it
    small = np.zeros((40, 40))
    small[20, 20] = 0.5
    (entry, exit_), _ = blob_passes(small, 1.0, lead=3.0, spacing=7.7)[0][0]
    assert np.linalg.norm(exit_ - entry) == pytest.approx(3.0)  # a one-cell blob: a pass of the run-up's length
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
@given(
    st.floats(-50, 50),
    st.floats(-50, 50),
    st.floats(-math.pi, math.pi),
    st.floats(-50, 50),
    st.floats(-50, 50),
    st.sampled_from([0.0, 0.3, 0.5, 0.6]),
)
@example(0.0, 1.0, 3.1415926535897927, 1.0, 1.0, 0.0)  # the carrot straight behind: (2/π)|e_θ| rounded past 2
def test_the_pursuit_law_keeps_the_papers_velocity_bounds(x, y, theta, goal_x, goal_y, weave):
    """With or without a weave (model.controllers.anicov.weave): eq. 15-16's bounds |v| ≤ k_v, |ω| ≤ π k_ω."""
    v, omega = pursuit_law(x, y, theta, goal_x, goal_y, 1.0, 1.0, 0.1, weave, 3.5)
    assert abs(v) <= 1.0 and abs(omega) <= math.pi + 1e-12


@settings(max_examples=200)
@given(st.floats(-50, 50), st.floats(-50, 50), st.floats(-math.pi, math.pi), st.floats(-50, 50), st.floats(-50, 50))
def test_the_pursuit_law_without_a_weave_is_pure_pursuit(x, y, theta, goal_x, goal_y):
    """Amplitude 0: v = k_v min(1, d/(k_v dt)) (1 - 2|e_θ|/π) (held at -k_v), ω = k_ω e_θ, bit for bit as
    the straight passes were flown before the weave (the strip's tables and ``weave = false`` rely on it)."""
    v, omega = pursuit_law(x, y, theta, goal_x, goal_y, 1.0, 1.0, 0.1)
    e_theta = wrap_angle(math.atan2(goal_y - y, goal_x - x) - theta)
    arrive = min(1.0, math.sqrt((goal_x - x) ** 2 + (goal_y - y) ** 2) / (1.0 * 0.1))
    assert v == 1.0 * arrive * max(-1.0, 1.0 - (2.0 / math.pi) * abs(e_theta))  # bit for bit: the same sums
    assert omega == e_theta


def test_best_names_the_anicov_controller_which_flies_stations_among_walls_and_plans_anywhere():
    assert PAPER.with_overrides(controller="best").controller == "anicov"
    assert PAPER.with_overrides(controller="anicov").plan_steps == 5  # a carrot every 0.5 time units
    assert PAPER.with_overrides(controller="anicov", robot_radius=0.5, stations=True).has_terrain
    with pytest.raises(ScenarioError, match="'stations': false flies anicov's weaving spiral, which knows no walls"):
        PAPER.with_overrides(controller="anicov", robot_radius=0.5, stations=False)
    assert PAPER.with_overrides(controller="anicov", planning="local").planning == "local"  # issue 36, item 3
    assert PAPER.with_overrides(controller="anicov", robot_radius=0.5, stations=True, planning="local").has_terrain


@pytest.mark.parametrize("radius", [0.0, 0.5], ids=["open", "bodies"])
def test_every_robot_cuts_the_same_routes_at_its_first_local_plan_whoever_it_hears(radius):
    """planning = "local": a robot that hears no teammate at its first plan cuts the team's routes from their
    seeded start poses, which are where they stand: the routes are the ones the whole team's plan cuts."""
    scenario = PAPER.with_overrides(
        domain=[40.0, 40.0], agents=3, controller="anicov", robot_radius=radius, stations=True
    )
    start = starting_poses(scenario)[:, :2]
    lack = np.ones(scenario.grid_shape)
    team = LanePlanner(scenario)
    team.plan(lack, start)
    for me in range(3):
        alone = LanePlanner(scenario)
        alone.plan(lack, start[[me]], [me])
        for agent in range(3):
            assert np.array_equal(alone.routes[agent].points, team.routes[agent].points)
