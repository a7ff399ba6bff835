import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.sparse import csc_matrix

import model.controllers.anicov.stations as stations_module
from model.controllers.anicov.lane_planner import LOOKAHEAD, STARE_DISTANCE, STARE_PERIODS, LanePlanner
from model.controllers.anicov.route import FACE_RADIUS, Route, Stop
from model.controllers.anicov.stations import (
    BEARINGS,
    SPACINGS_PER_RANGE,
    bearing_sequence,
    grid,
    layout,
    station_routes,
    station_times,
    timeline,
    whole_periods,
    with_patched_stops,
)
from model.controllers.anicov.touch_ups import simulate_routes
from model.scenario import load_scenario

PAPER = Path(__file__).resolve().parents[1] / "scenarios" / "paper.toml"
STEP = 2.0 * math.pi / BEARINGS


def paper(agents: int = 4):
    return dataclasses.replace(load_scenario(PAPER), controller="anicov", stations=True, agents=agents)


def test_grid_is_a_serpentine_inside_the_margin():
    points = grid(100.0, 100.0, 25.0, 3.0, by_columns=False)
    assert len(points) == 25
    assert points.min() == 3.0 and points.max() == 97.0
    hops = np.linalg.norm(np.diff(points, axis=0), axis=1)
    assert np.allclose(hops, 23.5)  # row by row, turning at each row's end: no diagonal hop
    columns = grid(100.0, 50.0, 25.0, 3.0, by_columns=True)
    assert np.allclose(np.diff(columns[:3, 0]), 0.0)  # column by column


def test_bearing_sequence_sweeps_the_needed_bearings_once():
    last = BEARINGS - 1
    periods = np.zeros(BEARINGS, dtype=int)
    periods[[last - 1, last, 0, 1]] = [1, 2, 1, 3]  # a fan across bearing 0
    sequence = bearing_sequence(periods)
    assert [round(b / STEP) % BEARINGS for b in sequence] == [last - 1, last, last, 0, 1, 1, 1]
    # From the other end when the robot comes in facing it, and one more period facing the way out.
    back = bearing_sequence(periods, arrive=1 * STEP, leave=math.pi)
    assert [round(b / STEP) % BEARINGS for b in back] == [1, 1, 1, 0, last, last, last - 1, BEARINGS // 2]
    # Bearings more than a period's turn (90°) apart get one in between.
    step = BEARINGS // 4
    apart = np.zeros(BEARINGS, dtype=int)
    apart[[0, step + 2]] = 1
    assert [round(b / STEP) % BEARINGS for b in bearing_sequence(apart)] == [0, step, step + 2]
    assert bearing_sequence(np.zeros(BEARINGS, dtype=int)) == []


def test_layout_and_timeline_hold_every_period():
    scenario = paper()
    chosen = layout(scenario, by_columns=False)
    assert len(chosen.stations) == len(chosen.bearings) == 25
    periods = sum(len(b) for b in chosen.bearings)
    line = timeline(chosen, scenario.k_v)
    hops = float(np.linalg.norm(np.diff(chosen.stations, axis=0), axis=1).sum())
    assert line.length == pytest.approx(hops + periods * 0.5)


@pytest.mark.parametrize("agents", [1, 4])
def test_station_routes_share_out_every_period_and_cover_the_domain(agents):
    scenario = paper(agents)
    positions = np.random.default_rng(3).uniform(0.0, 100.0, (agents, 2))
    routes, stops, finish = station_routes(scenario, positions)
    assert finish > 0.0
    assert len(routes) == len(stops) == agents
    for route, position in zip(routes, positions, strict=True):
        assert np.allclose(route[0], position)
    shared = sum(len(stop.bearings) for robot in stops for stop in robot)
    expected = [sum(len(b) for b in layout(scenario, by_columns).bearings) for by_columns in (False, True)]
    assert shared in expected  # a cut inside a station's periods gives each side whole periods, none twice
    lack, _, _ = simulate_routes(scenario, routes, positions, LOOKAHEAD, stops=stops)
    assert (lack > 0.0).mean() < 0.03  # the programme's stares and hops, flown by the law, leave a little
    patched, flown = with_patched_stops(scenario, routes, stops, positions, LOOKAHEAD)
    added = sum(len(stop.bearings) for robot in patched for stop in robot) - shared
    assert added < 0.05 * shared
    assert (added > 0) == bool((lack > 0.0).any())
    assert [[stop.at for stop in robot] for robot in patched] == [[stop.at for stop in robot] for robot in stops]
    again = simulate_routes(scenario, routes, positions, LOOKAHEAD, stops=patched)
    assert not (again[0] > 0.0).any()  # the periods put in where the flight fell short finish it
    assert all(np.array_equal(a, b) for a, b in zip(flown, again, strict=True))  # the flight returned is theirs


def test_whole_periods_cover_every_cell_with_fewer_periods_than_rounding_up():
    rng = np.random.default_rng(5)
    stares = csc_matrix(rng.uniform(0.0, 1.0, (60, 12)) * (rng.uniform(size=(60, 12)) < 0.3))
    need = np.where(np.asarray(stares.sum(axis=1)).ravel() > 0.0, 3.0, 0.0)
    relaxed = linprog(np.ones(12), A_ub=-stares, b_ub=-need, bounds=(0, None), method="highs").x
    assert (relaxed % 1.0 > 1e-6).sum() >= 3  # a programme with fractions to round
    periods = whole_periods(stares, need, relaxed)
    assert periods.dtype.kind == "i"
    assert (periods >= np.floor(relaxed + 1e-6)).all()  # the programme's periods rounded down are kept
    assert (stares @ periods >= need - 1e-9).all()
    assert periods.sum() < np.ceil(relaxed - 1e-6).sum()
    # The first period added is where it brings the most of what is missing.
    missing = np.maximum(need - stares @ np.floor(relaxed + 1e-6), 0.0)
    gains = [np.minimum(stares[:, k].toarray().ravel(), missing).sum() for k in range(12)]
    assert periods[int(np.argmax(gains))] > np.floor(relaxed[int(np.argmax(gains))] + 1e-6)
    with pytest.raises(ValueError, match="no stare reaches"):
        unreached = csc_matrix(np.vstack([stares.toarray(), np.zeros((1, 12))]))  # a cell no stare reaches
        whole_periods(unreached, np.ones(61), np.zeros(12))


def test_layout_takes_the_spacing_of_least_time():
    scenario = paper()
    chosen = layout(scenario, by_columns=False)
    finishes = []
    for share in SPACINGS_PER_RANGE:  # on the paper's square: 6 × 6 stations 18.8 apart, or 5 × 5 23.5 apart
        candidate = stations_module._programme(scenario, grid(100.0, 100.0, share * scenario.range, 3.0, False))
        finishes.append((float(station_times(candidate, scenario.k_v)[1][-1]), len(candidate.stations)))
    assert sorted(count for _, count in finishes) == [25, 36]
    assert (float(station_times(chosen, scenario.k_v)[1][-1]), len(chosen.stations)) == min(finishes)
    assert len(chosen.stations) == 25  # 1,175.5 time units against 1,199 (the hops of 36 cost more than they save)


def test_route_stands_at_its_stop_for_each_bearing_then_goes_on():
    route = Route.of(np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]), stops=[Stop(10.0, [0.5, 1.0])])
    route.progress = 5.0
    assert np.allclose(route.carrot(np.array([5.0, 0.0]), 2.0, FACE_RADIUS), [7.0, 0.0])
    route.progress = 9.0
    route.advance(np.array([9.5, 0.0]), 2.0)
    assert np.allclose(route.carrot(np.array([9.5, 0.0]), 2.0, FACE_RADIUS), [10.0, 0.0])  # held at the stop
    at = np.array([10.0, 0.01])
    first = route.carrot(at, 2.0, FACE_RADIUS)
    assert np.linalg.norm(first - at) < FACE_RADIUS
    assert math.atan2(*(first - at)[::-1]) == pytest.approx(0.5)
    assert not route.done()
    second = route.carrot(at, 2.0, FACE_RADIUS)
    assert math.atan2(*(second - at)[::-1]) == pytest.approx(1.0)
    assert not route.stops
    route.advance(at, 2.0)
    assert np.allclose(route.carrot(at, 2.0, FACE_RADIUS), [10.0, 2.01])  # on along the route


def test_route_doubling_back_past_the_robot_never_leaves_it_standing():
    route = Route.of(np.array([[0.0, 0.0], [0.0, 11.0], [0.0, 0.0], [20.0, 0.0]]))
    route.progress = 10.0
    at = np.array([0.0, 10.0])
    # 2 ahead along the route is (0, 10) again, on the way back: a carrot on the robot would leave it
    # standing (the law faces a carrot that near) with its progress never moving on.
    assert np.allclose(route.carrot(at, 2.0, FACE_RADIUS), [0.0, 8.0])
    assert route.progress == pytest.approx(12.0)


def test_the_planner_leads_robots_to_their_stations_and_a_robot_with_nothing_left_stays():
    scenario = paper(2).with_overrides(domain=[40.0, 40.0])
    planner = LanePlanner(scenario)
    positions = np.array([[5.0, 5.0], [35.0, 30.0]])
    targets = planner.plan(np.ones(scenario.grid_shape), positions)
    for agent in (0, 1):
        route = planner.routes[agent]
        assert route.stops  # each has stations to stand at
        assert np.allclose(targets[agent], route.point_at(min(route.progress + LOOKAHEAD, route.stops[0].at)))
    for route in planner.routes.values():
        route.progress, route.stops = route.length, []  # both done, nothing uncovered
    assert np.allclose(planner.plan(np.zeros(scenario.grid_shape), positions), positions)


def test_a_free_robot_stares_at_a_blob_from_a_quarter_range_on_its_side():
    scenario = paper(1).with_overrides(domain=[40.0, 40.0])
    planner = LanePlanner(scenario)
    planner.routes[0] = Route.of(np.array([[2.0, 20.0]]))  # done with its route
    lack = np.zeros(scenario.grid_shape)
    lack[19:22, 29:32] = 1.0  # a blob about (30.5, 20.5)
    planner.plan(lack, np.array([[2.0, 20.0]]))
    route = planner.routes[0]
    stand = route.point_at(route.stops[0].at)
    assert np.linalg.norm(stand - [30.5, 20.5]) == pytest.approx(STARE_DISTANCE * scenario.range)
    assert stand[0] < 30.5  # on the robot's side
    assert route.stops[0].bearings == [pytest.approx(math.atan2(20.5 - stand[1], 30.5 - stand[0]))] * STARE_PERIODS


def test_a_stare_that_covered_nothing_is_not_given_again_from_the_same_place():
    scenario = paper(1).with_overrides(domain=[40.0, 40.0])
    planner = LanePlanner(scenario)
    planner.routes[0] = Route.of(np.array([[2.0, 20.0]]))
    lack = np.zeros(scenario.grid_shape)
    lack[19:22, 29:32] = 1.0
    where = np.array([[2.0, 20.0]])
    planner.plan(lack, where)
    stand = planner.routes[0].point_at(planner.routes[0].length)
    planner.routes[0] = Route.of(stand[None, :])  # the stare done, and the blob as it was
    planner.plan(lack, stand[None, :])
    assert not planner.routes[0].stops  # the blob's pass this time
    assert planner.routes[0].length > 0.0
    planner.routes[0] = Route.of(stand[None, :])  # back where it stared from (as if)
    lack[[19, 21], 29:32] = 0.0  # but something was covered since (the centroid is where it was): stare again
    planner.plan(lack, stand[None, :])
    assert planner.routes[0].stops
    assert np.allclose(planner.routes[0].point_at(planner.routes[0].length), stand)


def test_layouts_are_shared_by_every_team_seed_and_time_limit_of_a_domain():
    first = layout(paper(4), by_columns=True)
    assert layout(dataclasses.replace(paper(10), seed=7, max_time=50.0), by_columns=True) is first
    assert layout(paper(4).with_overrides(range=18.0), by_columns=True) is not first  # another sensor


def test_turning_in_puts_the_turn_from_the_way_in_before_the_first_stare_and_only_when_asked():
    periods = np.zeros(BEARINGS)
    periods[12] = 2  # facing pi
    plain = bearing_sequence(periods, 0.0, None, math.pi / 2)
    assert plain == [math.pi, math.pi]
    turned = bearing_sequence(periods, 0.0, None, math.pi / 2, turn_in=True)
    assert turned[-2:] == [math.pi, math.pi] and len(turned) == 3  # one period turning: half way round
    assert abs(math.remainder(turned[0], 2 * math.pi)) == pytest.approx(math.pi / 2)
    assert bearing_sequence(periods, math.pi, None, math.pi / 2, turn_in=True) == plain  # already facing it


def eager_whole_periods(stares, need, relaxed):
    """whole_periods as it was before the lazy greedy: every column's gain computed at every period."""
    periods = np.floor(relaxed + 1e-6)
    missing = need - stares @ periods
    by_column = stares.T.tocsr()
    clipped = by_column.copy()
    while (missing > 1e-9).any():
        clipped.data = np.minimum(by_column.data, np.maximum(missing, 0.0)[by_column.indices])
        gain = np.asarray(clipped.sum(axis=1)).ravel()
        best = int(np.argmax(gain))
        periods[best] += 1.0
        missing -= stares[:, best].toarray().ravel()
    return periods.astype(int)


def test_the_lazy_greedy_picks_the_periods_every_gain_computed_each_time_picks_ties_and_all():
    from scipy.sparse import random as sparse_random

    rng = np.random.default_rng(5)
    for trial in range(40):
        cells, columns = int(rng.integers(20, 120)), int(rng.integers(5, 60))
        stares = sparse_random(cells, columns, density=0.2, random_state=trial, format="csc")
        if trial % 2:
            stares.data = np.round(stares.data * 4) / 4 + 0.25  # few distinct values: many ties between columns
        reached = np.asarray(stares.sum(axis=1)).ravel() > 0
        need = np.where(reached, rng.uniform(0.5, 2.0, cells), 0.0)
        relaxed = rng.uniform(0.0, 1.5, columns)
        assert np.array_equal(whole_periods(stares, need, relaxed), eager_whole_periods(stares, need, relaxed))
