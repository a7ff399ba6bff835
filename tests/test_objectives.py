"""Algorithm 1 on shapes like the paper's Fig. 2 (separate blobs) and Fig. 3 (ring, C, L)."""

import numpy as np
import pytest
from scipy.ndimage import distance_transform_edt

from model.paper.objectives import BlobObjectives, by_paths_through, cell_of, fallback_objective, select_objectives

CELL = 1.0
R = 20.0


def lack_with(mask: np.ndarray) -> np.ndarray:
    return mask.astype(np.float64)


def check_invariants(lack: np.ndarray, result: BlobObjectives) -> None:
    """Every objective lies on an uncovered cell of its own blob; every uncovered cell has a blob."""
    assert result.labels is not None
    for j, point in enumerate(result.positions):
        row, col = cell_of(point, CELL, lack.shape)
        assert lack[row, col] > 0.0, f"objective {j} on a covered cell"
        assert result.labels[row, col] == j + 1, f"objective {j} outside its blob"
    uncovered = lack > 0.0
    assert (result.labels[uncovered] > 0).all()
    assert (result.labels[~uncovered] == 0).all() or result.count > 0


def test_three_separate_blobs_give_three_objectives_at_their_centroids():
    mask = np.zeros((100, 100), dtype=bool)
    mask[10:20, 10:30] = True
    mask[60:80, 15:25] = True
    mask[40:60, 70:95] = True
    result = select_objectives(lack_with(mask), BlobObjectives(), CELL, R)
    assert result.count == 3
    centres = sorted(map(tuple, result.positions.round(2)))
    assert centres == [(20.0, 15.0), (20.0, 70.0), (82.5, 50.0)]
    check_invariants(lack_with(mask), result)


def ring(size=100, outer=40, inner=30, inner_shift=0.0):
    rows, cols = np.mgrid[0:size, 0:size]
    radius = np.hypot(rows + 0.5 - size / 2, cols + 0.5 - size / 2)
    inner_radius = np.hypot(rows + 0.5 - size / 2, cols + 0.5 - size / 2 - inner_shift)
    return (radius <= outer) & (inner_radius >= inner)


def eccentric_ring():
    """A ring, thin on one side (Fig. 3, top): erosion cuts the thin side first."""
    return ring(outer=42, inner=30, inner_shift=8.0)


def c_shape():
    """A C with a thinner back (Fig. 3, bottom): erosion splits it into its two arms."""
    mask = np.zeros((100, 100), dtype=bool)
    mask[10:90, 10:18] = True
    mask[10:30, 10:90] = True
    mask[70:90, 10:90] = True
    return mask


def l_shape():
    """An L with one thick arm: erosion removes the thin arm, the thick one keeps its centroid."""
    mask = np.zeros((100, 100), dtype=bool)
    mask[10:90, 10:24] = True
    mask[10:18, 10:90] = True
    return mask


@pytest.mark.parametrize("shape", [eccentric_ring, c_shape, l_shape], ids=["ring", "C", "L"])
def test_irregular_blobs_are_eroded_until_centroids_fall_inside(shape):
    mask = shape()
    lack = lack_with(mask)
    # The plain centroid of the whole shape is covered (Fig. 3): a naive law would stall there.
    rows, cols = np.nonzero(mask)
    assert not mask[int(rows.mean()), int(cols.mean())]
    result = select_objectives(lack, BlobObjectives(), CELL, R)
    assert result.count >= 1
    check_invariants(lack, result)


def test_objectives_persist_between_calls_and_covered_ones_are_dropped():
    mask = np.zeros((100, 100), dtype=bool)
    mask[10:20, 10:30] = True
    mask[60:80, 60:80] = True
    first = select_objectives(lack_with(mask), BlobObjectives(), CELL, R)
    again = select_objectives(lack_with(mask), first, CELL, R)
    assert np.array_equal(first.positions, again.positions)
    mask[60:80, 60:80] = False  # the second blob gets covered
    third = select_objectives(lack_with(mask), again, CELL, R)
    assert third.count == 1
    assert tuple(third.positions[0]) == (20.0, 15.0)


def test_objectives_closer_than_range_are_dropped_and_merged():
    previous = BlobObjectives(positions=np.array([[40.0, 50.0], [50.0, 50.0]]), labels=np.zeros((100, 100), np.int32))
    mask = np.zeros((100, 100), dtype=bool)
    mask[45:55, 35:55] = True
    previous.labels[45:55, 35:45] = 1
    previous.labels[45:55, 45:55] = 2
    result = select_objectives(lack_with(mask), previous, CELL, R)
    assert result.count == 1  # both dropped (10 < R apart), then found again as one blob
    assert tuple(result.positions[0]) == (45.0, 50.0)


def test_thin_symmetric_ring_erodes_away_and_falls_back_to_nearest_uncovered_point():
    mask = ring(outer=31, inner=30)
    lack = lack_with(mask)
    result = select_objectives(lack, BlobObjectives(), CELL, R)
    assert result.count == 0
    agents = np.array([[50.0, 50.0], [95.0, 50.0]])
    fallback = fallback_objective(lack, agents, CELL)
    assert fallback is not None
    row, col = cell_of(fallback, CELL, lack.shape)
    assert mask[row, col]
    assert np.linalg.norm(fallback - agents[1]) < 16.0


def test_fallback_is_none_when_all_covered():
    assert fallback_objective(np.zeros((5, 5)), np.array([[1.0, 1.0]]), CELL) is None


@pytest.mark.parametrize("shape", [ring, l_shape, c_shape], ids=["ring", "L", "C"])
def test_objectives_of_fig3_shapes_spread_over_the_shape(shape):
    """Eroded cells go to the nearest blob: blobs partition the shape, objectives differ."""
    mask = shape()
    result = select_objectives(lack_with(mask), BlobObjectives(), CELL, R)
    if result.count == 0:
        pytest.skip("uniform shape erodes away: covered by the fallback test")
    assert set(np.unique(result.labels[mask])) == set(range(1, result.count + 1))


def u_beside_a_square() -> np.ndarray:
    """A 10 x 10 blob left of a wall (column 15, never uncovered) and, right of it, a thin U whose
    centroid lies in its hollow: it erodes away without becoming a blob, so line 25 places its cells."""
    mask = np.zeros((30, 30), dtype=bool)
    mask[10:20, 2:12] = True
    mask[8:22, 18] = True  # the U: two arms and a bottom
    mask[8:22, 24] = True
    mask[8, 18:25] = True
    return lack_with(mask)


def test_in_the_open_line_25_gives_eroded_cells_to_the_straight_nearest_blob():
    lack = u_beside_a_square()
    result = select_objectives(lack, BlobObjectives(), CELL, R)
    assert result.count == 1  # the U's cells went to the square's blob, across the wall
    assert (result.labels[lack > 0] == 1).all()


def test_on_a_terrain_eroded_cells_no_blob_reaches_through_uncovered_cells_get_their_own_objective():
    lack = u_beside_a_square()
    result = select_objectives(lack, BlobObjectives(), CELL, R, by_paths=True)
    check_invariants(lack, result)
    assert result.count == 2
    u = result.labels[8, 18]
    right_of_the_wall = (lack > 0) & (np.arange(30) > 15)[None, :]
    assert u != result.labels[15, 5] and (result.labels[right_of_the_wall] == u).all()
    assert result.positions[u - 1][0] > 15.0  # its objective on its side of the wall, on one of its cells


def test_on_a_terrain_an_eroded_cell_takes_the_blob_its_uncovered_cells_reach_not_the_straight_nearest():
    """Blob 1 at the left, blob 2 just across a wall from the eroded cells, which a strip of uncovered cells
    joins to blob 1 only."""
    uncovered = np.zeros((12, 20), dtype=bool)
    labels = np.zeros((12, 20), dtype=np.int32)
    uncovered[0:4, 0:4] = True
    labels[0:4, 0:4] = 1  # blob 1
    uncovered[8:12, 14:18] = True
    labels[8:12, 14:18] = 2  # blob 2, beyond the wall (row 7 is never uncovered)
    uncovered[2, 4:16] = True  # eroded: a strip from blob 1 ...
    uncovered[2:6, 15] = True  # ... ending 2 cells from blob 2, across the wall
    eroded = uncovered & (labels == 0)
    positions = [np.array([2.0, 2.0]), np.array([16.0, 10.0])]
    result = by_paths_through(uncovered, labels, eroded, positions, CELL)
    assert (result[eroded] == 1).all() and len(positions) == 2
    # The straight nearest blob, as in the open, gives the strip's end to blob 2.
    _, nearest = distance_transform_edt(labels == 0, return_indices=True)
    assert labels[nearest[0][5, 15], nearest[1][5, 15]] == 2
