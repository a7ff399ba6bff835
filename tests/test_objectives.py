"""Algorithm 1 on shapes like the paper's Fig. 2 (separate blobs) and Fig. 3 (ring, C, L)."""

import numpy as np
import pytest

from model.objectives import BlobObjectives, cell_of, fallback_objective, select_objectives

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
