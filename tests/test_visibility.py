"""model.world.visibility: walls and teammates hide cells; free space hides nothing."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from model.world.visibility import line_of_sight, segment_crosses_occupied, segment_passes_disk

NOBODY = np.zeros((0, 2))


def wall_grid() -> np.ndarray:
    """20 × 20 cells of 1, a wall in column 10 from row 0 to row 14."""
    occupied = np.zeros((20, 20), dtype=bool)
    occupied[0:15, 10] = True
    return occupied


def test_a_wall_hides_what_is_behind_it_and_not_what_is_beside_it():
    occupied = wall_grid()
    assert not line_of_sight(occupied, 5.5, 5.5, 15.5, 5.5, 1.0, NOBODY, 0.0)  # straight through the wall
    assert line_of_sight(occupied, 5.5, 5.5, 9.5, 5.5, 1.0, NOBODY, 0.0)  # in front of it
    assert line_of_sight(occupied, 5.5, 17.5, 15.5, 17.5, 1.0, NOBODY, 0.0)  # above its end
    assert not line_of_sight(occupied, 5.5, 5.5, 15.5, 14.2, 1.0, NOBODY, 0.0)  # slanting into it


def test_the_end_cells_are_not_tested():
    occupied = wall_grid()
    assert not segment_crosses_occupied(occupied, 10.5, 5.5, 10.5, 6.5, 1.0)  # both ends in the wall
    assert not segment_crosses_occupied(occupied, 9.5, 5.5, 10.5, 5.5, 1.0)  # the target is the wall's face


def test_a_diagonal_staircase_wall_does_not_leak_at_its_corners():
    occupied = np.zeros((10, 10), dtype=bool)
    for k in range(10):
        occupied[k, 9 - k] = True  # cells touching only at corners
    assert segment_crosses_occupied(occupied, 0.5, 0.5, 9.5, 9.5, 1.0)  # through the corners of the stair


def test_a_teammate_hides_the_cells_behind_its_disk_but_not_beside_it():
    free = np.zeros((20, 20), dtype=bool)
    teammate = np.array([[10.0, 5.5]])
    assert not line_of_sight(free, 5.5, 5.5, 15.5, 5.5, 1.0, teammate, 0.5)
    assert line_of_sight(free, 5.5, 5.5, 15.5, 7.5, 1.0, teammate, 0.5)  # passes 0.99 from its centre
    assert line_of_sight(free, 5.5, 5.5, 15.5, 5.5, 1.0, teammate, 0.0)  # point robots hide nothing
    assert not segment_passes_disk(0.0, 0.0, 1.0, 0.0, 1.5, 0.0, 0.5)  # beyond the segment's end


coordinate = st.floats(0.0, 20.0, allow_nan=False)


@given(coordinate, coordinate, coordinate, coordinate)
def test_an_empty_grid_never_blocks(x0, y0, x1, y1):
    assert line_of_sight(np.zeros((20, 20), dtype=bool), x0, y0, x1, y1, 1.0, NOBODY, 0.0)


@given(coordinate, coordinate, coordinate, coordinate)
def test_the_traversal_blocks_exactly_when_a_dense_sample_of_the_segment_meets_an_inner_occupied_cell(x0, y0, x1, y1):
    occupied = wall_grid()
    start, end = (math.floor(x0), math.floor(y0)), (math.floor(x1), math.floor(y1))
    hit = False
    for t in np.linspace(0.0, 1.0, 4001)[1:-1]:
        col, row = math.floor(x0 + t * (x1 - x0)), math.floor(y0 + t * (y1 - y0))
        if (col, row) not in (start, end) and 0 <= row < 20 and 0 <= col < 20 and occupied[row, col]:
            hit = True
            break
    blocked = segment_crosses_occupied(occupied, x0, y0, x1, y1, 1.0)
    # Sampling can miss a cell the segment only clips; the traversal never misses one it samples.
    assert blocked or not hit
