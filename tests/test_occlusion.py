"""model.world.occlusion: the pruning never changes what the rule of model.world.visibility hides."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from model.paper.fixed_point import COVERAGE_SCALE
from model.paper.sensing import offset_from_heading, wedge_reach
from model.world.ground import NO_POSITIONS, Ground
from model.world.occlusion import _square_span, _square_span_by_corners
from model.world.visibility import line_of_sight
from model.world.wedge import sense_wedge

R, F, ALPHA, TARGET = 20.0, math.radians(27.0), 50.0, 100 * COVERAGE_SCALE


@settings(max_examples=150)
@given(st.integers(0, 2**32 - 1), st.floats(-math.pi, math.pi), st.sampled_from([0.0, 0.6]))
def test_the_pruned_wedge_hides_exactly_what_the_rule_hides(seed, theta, radius):
    rng = np.random.default_rng(seed)
    occupied = rng.random((40, 40)) < 0.04
    x, y = rng.uniform(10.0, 30.0, 2)
    occupied[int(y), int(x)] = False  # the robot never stands in an occupied cell
    # Teammates anywhere, and close round the robot (beside and behind it too, where disks cross its
    # sideways line).
    around = rng.uniform(1.2, 4.0, 3)[:, None] * np.stack(
        [np.cos(angles := rng.uniform(-np.pi, np.pi, 3)), np.sin(angles)], 1
    )
    positions = np.array([[x, y], *rng.uniform(0.0, 40.0, (3, 2)), *(np.array([x, y]) + around)])
    coverage = np.zeros((40, 40), dtype=np.int64)
    ground = Ground(occupied, ~occupied, radius, radius, radius, False, True, True, 20, occupied, 1.0)
    blind = ground._replace(occlusion=False)
    e_seen, *_, row0, col0, seen = sense_wedge(
        coverage, TARGET, x, y, theta, R, F, ALPHA, 0.1, 1.0, ground, positions, 0
    )
    e_everything, *_, row0b, col0b, everything = sense_wedge(
        coverage, TARGET, x, y, theta, R, F, ALPHA, 0.1, 1.0, blind, NO_POSITIONS, 0
    )
    assert (row0, col0, seen.shape) == (row0b, col0b, everything.shape)
    others = positions[1:][np.hypot(*(positions[1:] - [x, y]).T) >= 2 * radius]  # overlapping bodies hide nothing
    # The wedge's cells on the grid, by the pass's own test of eq. 2's support, not by their ticks: a centre
    # just inside R or F has an ability that rounds to no tick (seed 94682763: r = R − 6e-8), yet it lacks
    # coverage and counts in e_Ω like any other.
    heading_x, heading_y = math.cos(theta), math.sin(theta)
    in_wedge = visible_in_wedge = 0
    for i, j in np.ndindex(everything.shape):
        distance, along, across = wedge_reach(
            col0 + j + 0.5 - x, row0 + i + 0.5 - y, heading_x, heading_y, R, math.cos(F)
        )
        if distance < 0.0 or offset_from_heading(distance, along, across) > F:
            assert everything[i, j] == 0 and seen[i, j] == 0
            continue
        visible = line_of_sight(occupied, x, y, (col0 + j + 0.5), (row0 + i + 0.5), 1.0, others, radius)
        in_wedge, visible_in_wedge = in_wedge + 1, visible_in_wedge + visible
        assert seen[i, j] == (everything[i, j] if visible else 0)
    # e_Ω on a fresh map: the visible cells' lack over every cell of the wedge, hidden or off the grid
    # (the pass counts a hidden cell without its arctangent where the cone's cheap test settles it).
    assert e_seen * in_wedge == pytest.approx(e_everything * visible_in_wedge, rel=1e-12)


@settings(max_examples=150)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(40, 120),
    st.integers(40, 120),
    st.sampled_from([k * math.pi / 8 for k in range(-8, 8)] + [math.atan2(1, 2), math.atan2(-2, 1)]),
)
def test_pruning_is_exact_on_grid_lines_corners_and_diagonals(seed, quarter_x, quarter_y, theta):
    """Robots on cell edges, corners and centres, looking along axes and diagonals: segments through
    grid corners and along grid lines, where the traversal's tie rules decide, and squares beside the
    robot whose edges cross its sideways line."""
    rng = np.random.default_rng(seed)
    occupied = rng.random((40, 40)) < 0.15
    x, y = quarter_x / 4.0, quarter_y / 4.0
    occupied[int(y), int(x)] = False
    coverage = np.zeros((40, 40), dtype=np.int64)
    ground = Ground(occupied, ~occupied, 0.0, 0.0, 0.0, False, True, True, 20, occupied, 1.0)
    positions = np.array([[x, y]])
    *_, row0, col0, seen = sense_wedge(coverage, TARGET, x, y, theta, R, F, ALPHA, 0.1, 1.0, ground, positions, 0)
    blind = ground._replace(occlusion=False)
    *_, _, _, everything = sense_wedge(coverage, TARGET, x, y, theta, R, F, ALPHA, 0.1, 1.0, blind, NO_POSITIONS, 0)
    for i, j in zip(*np.nonzero(everything), strict=True):
        visible = line_of_sight(occupied, x, y, (col0 + j + 0.5), (row0 + i + 0.5), 1.0, NO_POSITIONS, 0.0)
        assert seen[i, j] == (everything[i, j] if visible else 0)


@settings(max_examples=150)
@given(st.integers(0, 2**32 - 1), st.floats(-math.pi, math.pi))
def test_teammates_beside_and_behind_hide_exactly_what_the_rule_hides(seed, theta):
    """No wall: only teammates' disks prune, close round the robot, in front, beside and behind it."""
    rng = np.random.default_rng(seed)
    occupied = np.zeros((40, 40), dtype=np.bool_)
    x, y = rng.uniform(15.0, 25.0, 2)
    angles = rng.uniform(-np.pi, np.pi, 5)
    around = rng.uniform(1.2, 5.0, 5)[:, None] * np.stack([np.cos(angles), np.sin(angles)], 1)
    positions = np.array([[x, y], *(np.array([x, y]) + around)])
    coverage = np.zeros((40, 40), dtype=np.int64)
    ground = Ground(occupied, ~occupied, 0.6, 0.6, 0.6, False, True, True, 20, occupied, 1.0)
    *_, row0, col0, seen = sense_wedge(coverage, TARGET, x, y, theta, R, F, ALPHA, 0.1, 1.0, ground, positions, 0)
    blind = ground._replace(occlusion=False)
    *_, _, _, everything = sense_wedge(coverage, TARGET, x, y, theta, R, F, ALPHA, 0.1, 1.0, blind, NO_POSITIONS, 0)
    for i, j in zip(*np.nonzero(everything), strict=True):
        visible = line_of_sight(occupied, x, y, (col0 + j + 0.5), (row0 + i + 0.5), 1.0, positions[1:], 0.6)
        assert seen[i, j] == (everything[i, j] if visible else 0)


def test_a_diagonal_through_grid_corners_is_pruned_as_the_traversal_decides():
    """A case found by a search over quarter-cell positions: the segment from (24.75, 15.25) to the centre
    of cell (9, 30) runs exactly through grid corners, and without a slack on the squares' spans (the bins
    they mark) the pruning called a cell in sight that the traversal's corner rule hides."""
    occupied = np.random.default_rng(1721).random((40, 40)) < 0.15
    x, y, theta = 24.75, 15.25, -math.pi / 4
    occupied[int(y), int(x)] = False
    coverage = np.zeros((40, 40), dtype=np.int64)
    ground = Ground(occupied, ~occupied, 0.0, 0.0, 0.0, False, True, True, 20, occupied, 1.0)
    *_, row0, col0, seen = sense_wedge(
        coverage, TARGET, x, y, theta, R, F, ALPHA, 0.1, 1.0, ground, np.array([[x, y]]), 0
    )
    blind = ground._replace(occlusion=False)
    *_, _, _, everything = sense_wedge(coverage, TARGET, x, y, theta, R, F, ALPHA, 0.1, 1.0, blind, NO_POSITIONS, 0)
    assert not line_of_sight(occupied, x, y, 30.5, 9.5, 1.0, NO_POSITIONS, 0.0)
    assert everything[9 - row0, 30 - col0] > 0 and seen[9 - row0, 30 - col0] == 0
    for i, j in zip(*np.nonzero(everything), strict=True):
        visible = line_of_sight(occupied, x, y, (col0 + j + 0.5), (row0 + i + 0.5), 1.0, NO_POSITIONS, 0.0)
        assert seen[i, j] == (everything[i, j] if visible else 0)


@settings(max_examples=300)
@given(st.floats(-8.0, 8.0), st.floats(-8.0, 8.0), st.floats(-math.pi, math.pi), st.booleans())
def test_a_square_seen_from_outside_spans_what_its_four_corners_span(left, bottom, theta, on_grid_lines):
    """The span's ends taken from the two corners where the robot lies equal the corners' extremes (to
    the last bits: corners on one bearing round apart), squares beside and behind the robot included."""
    if on_grid_lines:
        left, bottom = float(round(left)), float(round(bottom))
    if left <= 0.0 <= left + 1.0 and bottom <= 0.0 <= bottom + 1.0:
        return  # the robot on or in the square: only the corners' rule applies
    heading_x, heading_y = math.cos(theta), math.sin(theta)
    smallest, largest, farthest2, behind = _square_span(left, bottom, 1.0, heading_x, heading_y)
    by_corners = _square_span_by_corners(left, bottom, 1.0, heading_x, heading_y)
    assert (farthest2, behind) == by_corners[2:]
    assert smallest == pytest.approx(by_corners[0], abs=1e-14)
    assert largest == pytest.approx(by_corners[1], abs=1e-14)
