"""model.world.clearance: a robot in a corridor never touches its walls, and never leaves a map."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from model.world.clearance import _segment_square_distance2, disk_is_free, step_or_stay, swept_disk_is_free


def corridor() -> np.ndarray:
    """30 × 30 cells of 1: walls in rows 9 and 13, a corridor of free rows 10–12 (y from 10 to 13)."""
    occupied = np.zeros((30, 30), dtype=bool)
    occupied[9, :] = True
    occupied[13, :] = True
    return occupied


def test_the_disk_test_measures_to_the_cells_squares():
    walls = corridor()
    assert disk_is_free(walls, 5.0, 11.5, 1.4, 1.0, False)  # 1.5 from each wall
    assert not disk_is_free(walls, 5.0, 11.5, 1.6, 1.0, False)
    assert not disk_is_free(walls, 5.0, 9.5, 0.0, 1.0, False)  # a point robot inside a wall cell
    assert not disk_is_free(walls, 5.0, 10.0, 0.0, 1.0, False)  # on the wall's face: touching counts
    assert disk_is_free(walls, 5.0, 10.01, 0.0, 1.0, False)


def test_a_map_bounds_the_robot_and_an_open_domain_does_not():
    free = np.zeros((10, 10), dtype=bool)
    assert not disk_is_free(free, 0.2, 5.0, 0.5, 1.0, True)
    assert disk_is_free(free, 0.2, 5.0, 0.5, 1.0, False)
    assert disk_is_free(free, -3.0, 5.0, 0.5, 1.0, False)  # the paper's robots may leave the domain


def test_a_blocked_step_keeps_the_position_and_takes_the_turn():
    walls = corridor()
    x, y, theta = step_or_stay(walls, 5.0, 11.5, math.pi / 2, 2.0, 0.5, 1.0, 0.5, 1.0, False)  # ends near y = 13.4
    assert (x, y) == (5.0, 11.5) and theta == math.pi / 2 + 0.5


@given(
    st.floats(0.5, 29.5),
    st.floats(-math.pi, math.pi),
    st.lists(st.tuples(st.floats(0.0, 1.0), st.floats(-math.pi, math.pi)), min_size=1, max_size=200),
)
def test_a_robot_driven_anyhow_in_a_corridor_never_touches_its_walls(x, theta, commands):
    walls, radius = corridor(), 0.5
    y = 11.5
    for v, omega in commands:
        x, y, theta = step_or_stay(walls, x, y, theta, v, omega, 0.7, radius, 1.0, True)
        assert 10.0 + radius <= y <= 13.0 - radius
        assert disk_is_free(walls, x, y, radius, 1.0, True)


@settings(max_examples=200)
@given(st.integers(0, 2**32 - 1), st.floats(0.05, 1.5))
def test_the_swept_disk_test_is_exact_against_dense_sampling(seed, radius):
    rng = np.random.default_rng(seed)
    occupied = rng.random((12, 12)) < 0.15
    (x0, y0), (x1, y1) = rng.uniform(0.0, 12.0, (2, 2))
    samples = [(x0 + t * (x1 - x0), y0 + t * (y1 - y0)) for t in np.linspace(0.0, 1.0, 2001)]
    free = swept_disk_is_free(occupied, x0, y0, x1, y1, radius, 1.0, False)
    if free:  # no sample's disk overlaps (a hair smaller, for the touching case)
        assert all(disk_is_free(occupied, x, y, radius * (1 - 1e-6), 1.0, False) for x, y in samples)
    else:  # some sample's disk, a hair larger, does
        assert not all(disk_is_free(occupied, x, y, radius + 0.01, 1.0, False) for x, y in samples)


@settings(max_examples=300)
@given(
    st.integers(0, 2**32 - 1),
    st.sampled_from([0.0, 0.05, 0.4, 0.45, 1.0, 2.3]),
    st.sampled_from(["any", "horizontal", "vertical", "on lines"]),
)
def test_the_swept_disk_test_answers_as_every_square_tested(seed, radius, kind):
    """Row by row, the squares it tests are all those that can matter: the answer is that of the exact
    test on every occupied square of the map (segments along and on grid lines included)."""
    rng = np.random.default_rng(seed)
    occupied = rng.random((16, 16)) < 0.12
    (x0, y0), (x1, y1) = rng.uniform(0.0, 16.0, (2, 2))
    if kind == "horizontal":
        y1 = y0
    elif kind == "vertical":
        x1 = x0
    elif kind == "on lines":
        x0, y0, x1, y1 = (float(v) for v in rng.integers(0, 17, 4))
    everything = all(
        not occupied[r, c]
        or _segment_square_distance2(x0, y0, x1, y1, float(c), float(r), c + 1.0, r + 1.0) >= max(radius**2, 1e-300)
        for r in range(16)
        for c in range(16)
    )
    assert swept_disk_is_free(occupied, x0, y0, x1, y1, radius, 1.0, False) == everything
