"""model.world.geodesic: distance fields around walls, and a way to follow them that never stalls at a wall."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model.world.clearance import disk_is_free, step_or_stay
from model.world.geodesic import (
    descent_waypoint,
    distance_fields,
    entry_cell,
    length_by_field,
    passable_cells,
)


def wall_with_a_gap() -> np.ndarray:
    """40 × 40 cells of 1: a wall along column 20 from row 0 to row 31; the gap is above it."""
    occupied = np.zeros((40, 40), dtype=bool)
    occupied[0:32, 20] = True
    return occupied


def test_in_an_empty_grid_the_field_is_the_octile_distance():
    passable = np.ones((10, 10), dtype=bool)
    field = distance_fields(passable, [(2, 3)], 1.0)[0]
    for row, col in ((2, 3), (2, 9), (9, 3), (7, 8), (0, 0)):
        d_row, d_col = abs(row - 2), abs(col - 3)
        assert math.isclose(field[row, col], max(d_row, d_col) + (math.sqrt(2) - 1) * min(d_row, d_col))


def test_no_step_cuts_a_walls_corner_and_an_enclosed_room_is_unreachable():
    occupied = np.zeros((5, 5), dtype=bool)
    occupied[1, 2] = occupied[2, 1] = True  # (1,1) and (2,2) touch only at a corner of walls
    field = distance_fields(~occupied, [(1, 1)], 1.0)[0]
    assert field[2, 2] > math.sqrt(2) + 1e-9
    room = np.zeros((7, 7), dtype=bool)
    room[2:5, 2] = room[2:5, 4] = room[2, 2:5] = room[4, 2:5] = True
    assert np.isinf(distance_fields(~room, [(0, 0)], 1.0)[0][3, 3])


def test_the_radius_narrows_the_free_space():
    occupied = np.zeros((9, 9), dtype=bool)
    occupied[:, 4] = True
    occupied[4, 4] = False  # a one-cell doorway
    assert passable_cells(occupied, 0.4, 1.0, False)[4, 4]
    assert not passable_cells(occupied, 0.6, 1.0, False)[4, 4]  # the doorway is narrower than the robot


def test_with_the_objective_in_sight_the_global_law_is_the_papers():
    free = np.zeros((40, 40), dtype=bool)
    field = distance_fields(~free, [(30, 30)], 1.0)[0]
    assert descent_waypoint(field, ~free, free, 1.0, 5.0, 7.0, 30.5, 30.5, 1.0, 20, 0.5, True, 0.5) == (
        math.hypot(25.5, 23.5),
        30.5,
        30.5,
    )


def test_following_the_waypoints_gets_round_the_wall_where_heading_straight_stalls():
    occupied, radius = wall_with_a_gap(), 0.5
    goal = (30.5, 5.5)
    passable = passable_cells(occupied, radius, 1.0, True)
    field = distance_fields(passable, [(5, 30)], 1.0)[0]

    def drive(aim_at_waypoints: bool) -> float:
        x, y, theta = 5.5, 5.5, 0.0
        for _ in range(1500):
            target = (
                descent_waypoint(field, passable, occupied, 1.0, x, y, *goal, 1.0, 20, radius, True, radius)[1:]
                if aim_at_waypoints
                else goal
            )
            heading = math.atan2(target[1] - y, target[0] - x)
            turn = math.remainder(heading - theta, 2 * math.pi)
            x, y, theta = step_or_stay(occupied, x, y, theta, 1.0, turn / 0.1, 0.1, radius, 1.0, True)
            assert disk_is_free(occupied, x, y, radius, 1.0, True)
        return math.hypot(goal[0] - x, goal[1] - y)

    assert drive(aim_at_waypoints=False) > 10.0  # pressed against the wall
    assert drive(aim_at_waypoints=True) < 1.0


def test_a_robot_inside_the_planning_margin_joins_the_graph_beside_it_instead_of_heading_straight():
    """A robot the safety filter holds s off a wall stands inside the planning margin, in a cell the
    graph leaves out: it follows the field from the best cell beside it (issue 12's stalls on the maps),
    where the field at its own cell (+inf) once sent it straight at the objective, into the wall."""
    occupied, planning_radius = wall_with_a_gap(), 0.75
    goal = (30.5, 5.5)
    passable = passable_cells(occupied, planning_radius, 1.0, True)
    field = distance_fields(passable, [(5, 30)], 1.0)[0]
    x, y = 19.3, 5.5  # 0.7 from the wall (r + s): its cell's centre is 0.5 off it, not passable
    assert math.isinf(field[5, 19])
    row, col = entry_cell(field, occupied, 1.0, x, y, 1.0, planning_radius, True)
    assert (row, col) != (-1, -1) and math.isfinite(field[row, col]) and abs(col - 19) <= 2
    distance, _, waypoint_y = descent_waypoint(field, passable, occupied, 1.0, x, y, *goal, 1.0, 20, 0.75, True, 0.7)
    assert math.isfinite(distance) and distance > 2 * (32 - 5)  # round the wall's end, not through it
    assert waypoint_y > y  # up, toward the gap: not at the goal behind the wall
    assert length_by_field(field, occupied, 1.0, x, y, 1.0, planning_radius, True) == distance


def test_a_robot_past_its_cell_s_centre_with_nothing_in_sight_heads_on_along_the_walk_not_back():
    """The campus map (0.8 m cells, 0.16 m wall squares, a planning radius of 0.84 m), N = 1 seed 15: at
    (102.215, 145.258), a hair too near a wall for any drive along its walk, the robot was sent back to its own
    cell's centre (102.0, 145.2) behind it; reversing, it saw 4 cells along the walk, drove on, came back to this
    spot, and so round for 12,000 time units. Past its cell's centre it now heads for the walk's next cell."""
    from model.scenario import load_scenario
    from model.world.world import world_of
    from tests.test_real_maps import REAL, map_of

    campus = REAL / "malaga-campus.toml"
    map_of(campus)
    scenario = load_scenario(campus)
    world = world_of(scenario)
    ground, cell = world.ground, scenario.cell
    objective = (110.0, 134.8)
    field = world.field(*objective)

    def waypoint(x: float, y: float) -> tuple[float, float]:
        return descent_waypoint(
            field, ground.passable, ground.wall_grid, ground.grain, x, y, *objective, cell, ground.lookahead,
            ground.plan_radius, ground.bounded, ground.wall_clearance,
        )[1:]  # fmt: skip

    assert entry_cell(field, ground.wall_grid, ground.grain, 102.215, 145.258, cell, ground.plan_radius, True) == (
        181,
        127,
    )  # its own cell, whose centre is (102.0, 145.2)
    assert waypoint(102.215, 145.258) == pytest.approx((102.8, 145.2))  # the walk's next cell, ahead
    assert waypoint(102.205, 145.236) == pytest.approx((105.2, 145.2))  # a hair farther off the wall: 4 cells on
