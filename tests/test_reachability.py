"""model.world.reachability: an enclosed room and a pocket narrower than the robot cannot be covered; a cell seen
only through a gap narrower than the noise is unsure."""

from __future__ import annotations

import numpy as np

from model.scenario.terrain import load_occupancy_map, map_on_grid
from model.world.geodesic import passable_cells
from model.world.reachability import coverable_cells, nearest_reachable, reachable_cells, unsure_cells
from tests.conftest import ROOT


def test_a_closed_room_is_unreachable_and_unseen_and_the_rest_of_the_office_is_coverable():
    occupied = map_on_grid(load_occupancy_map(ROOT / "scenarios" / "maps" / "office.yaml"), 1.0)
    passable = passable_cells(occupied, 0.5, 1.0, True)
    coverable = coverable_cells(occupied, passable, [(50, 50)], 20.0, 1.0)
    assert not coverable[86:99, 86:99].any()  # the store room behind its walls
    free = ~occupied
    free[85:99, 85:99] = False
    assert coverable[free].all()  # every other free cell: the rooms are seen through their doors


def test_a_pocket_narrower_than_the_robot_is_not_reachable_but_may_be_seen():
    occupied = np.zeros((20, 20), dtype=bool)
    occupied[:, 10] = True
    occupied[9, 10] = False  # a one-cell gap in a wall
    thin, wide = passable_cells(occupied, 0.4, 1.0, True), passable_cells(occupied, 0.6, 1.0, True)
    assert reachable_cells(thin, [(5, 5)], 1.0)[5, 15]  # through the gap
    assert not reachable_cells(wide, [(5, 5)], 1.0)[5, 15]  # the robot does not fit through
    seen = coverable_cells(occupied, wide, [(5, 5)], 20.0, 1.0)
    assert seen[9, 14] and not seen[2, 15]  # through the gap in line, not round the wall
    assert not seen[occupied].any()


def test_an_objective_in_a_wall_or_a_pocket_moves_to_the_nearest_reachable_cell():
    reachable = np.zeros((10, 10), dtype=bool)
    reachable[:, :5] = True
    points = np.array([[2.2, 3.3], [7.5, 4.5], [50.0, 50.0]])
    moved = nearest_reachable(reachable, points, 1.0)
    assert moved[0].tolist() == [2.2, 3.3]  # already where a robot can go
    assert moved[1].tolist() == [4.5, 4.5]  # the nearest reachable cell centre
    assert moved[2].tolist() == [4.5, 9.5]  # off the grid: clamped, then moved


def test_a_point_past_the_edge_of_a_reachable_border_cell_is_moved_onto_the_grid():
    # A robot of an unbounded map (obstacles, no map) may stand past the domain's edge; clamped into the edge
    # cell it stayed off the grid, and the free path from it indexed past the field (issue 37's noisy rooms).
    reachable = np.ones((16, 24), dtype=bool)
    moved = nearest_reachable(reachable, np.array([[14.39, 16.22], [-0.3, 5.5], [3.0, 4.0]]), 1.0)
    assert moved[0].tolist() == [14.5, 15.5]
    assert moved[1].tolist() == [0.5, 5.5]
    assert moved[2].tolist() == [3.0, 4.0]  # x / cell on a cell's edge: its own cell, reachable


def gap_in_a_wall() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cells of 1 on six rows of three, walls in squares of 0.1: a wall fills row 2 but for a gap 0.2 wide about
    x = 1.5. The robots reach rows 0 and 1; the cells of column 1 above the wall are seen only through the gap.
    (wall_grid, reachable, coverable)."""
    wall_grid = np.zeros((60, 30), dtype=bool)
    wall_grid[20:30, :] = True
    wall_grid[20:30, 14:16] = False
    reachable = np.zeros((6, 3), dtype=bool)
    reachable[:2] = True
    coverable = reachable.copy()
    coverable[3:, 1] = True
    return wall_grid, reachable, coverable


def test_a_cell_seen_only_through_a_gap_narrower_than_the_spread_is_unsure_and_one_seen_wide_is_not():
    wall_grid, reachable, coverable = gap_in_a_wall()
    wide = unsure_cells(wall_grid, 0.1, reachable, coverable, 5.0, 1.0, 0.5)
    assert wide[4, 1] and wide[3, 1]  # from 0.5 off any reachable centre the gap is missed
    assert not wide[:2].any()  # a reachable cell sees itself
    narrow = unsure_cells(wall_grid, 0.1, reachable, coverable, 5.0, 1.0, 0.05)
    assert not narrow[4, 1] and not narrow[3, 1]  # 0.05 off (1.5, 1.5) the line still passes the gap
    assert not unsure_cells(wall_grid, 0.1, reachable, coverable, 5.0, 1.0, 0.0).any()  # no noise: none
    open_room = np.zeros_like(wall_grid)
    assert not unsure_cells(open_room, 0.1, reachable, coverable, 5.0, 1.0, 0.5).any()
