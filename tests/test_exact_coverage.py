"""model.radio.exact_coverage: the integer kernel gives the float kernel's ticks on all but a handful of cells,
and always the same integers (a digest of them is pinned: any CPU must reproduce it)."""

from __future__ import annotations

import hashlib
import math

import numpy as np
import pytest

from model.controllers import law_parameters
from model.parameters import coverage_map_of, exact_kernel_of
from model.radio.exact_coverage import event_ticks, event_window, exact_kernel
from model.scenario import PAPER_SCENARIO, load_scenario
from model.step import read_wedge
from model.world.world import world_of

PAPER = load_scenario(PAPER_SCENARIO)


def float_and_exact(scenario, poses):
    """Per pose, the float kernel's and the integer kernel's ticks, each on the whole grid."""
    grid = coverage_map_of(scenario)
    law, ground, kernel = law_parameters(scenario, grid), world_of(scenario).ground, exact_kernel_of(scenario)
    for x, y, theta in poses:
        *_, row0, col0, ticks = read_wedge(grid.coverage, x, y, theta, law, ground, np.zeros((0, 2)))  # no teammates
        exact_row0, exact_col0, exact = event_ticks(kernel, x, y, theta)
        float_map, exact_map = np.zeros(grid.shape, np.int64), np.zeros(grid.shape, np.int64)
        float_map[row0 : row0 + ticks.shape[0], col0 : col0 + ticks.shape[1]] = ticks
        exact_map[exact_row0 : exact_row0 + exact.shape[0], exact_col0 : exact_col0 + exact.shape[1]] = exact
        yield float_map, exact_map


def random_poses(count: int, seed: int, low: float = -15.0, high: float = 115.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(low, high, count), rng.uniform(low, high, count), rng.uniform(-4, 4, count)])


@pytest.mark.parametrize(
    "scenario",
    [
        PAPER,
        PAPER.with_overrides(range=7.5, half_angle_deg=80.0, alpha_max=3.0, cell=0.5, domain=(60.0, 40.0)),
        PAPER.with_overrides(range=12.0, half_angle_deg=130.0, dt=0.05),
    ],
    ids=["paper", "wide-fine", "beyond-a-right-angle"],
)
def test_the_integer_kernel_rounds_as_the_float_kernel_on_random_poses(scenario):
    """Measured on the paper's sensor: 2 cells of 2.5 million differ (20,000 poses), by one tick (a value within 1e-5
    tick of a half, which either kernel may round either way)."""
    sensed = differing = 0
    for float_map, exact_map in float_and_exact(scenario, random_poses(4000, seed=5)):
        sensed += int(((float_map > 0) | (exact_map > 0)).sum())
        differ = float_map != exact_map
        differing += int(differ.sum())
        assert np.abs(float_map - exact_map).max() <= 1
    assert sensed > 100_000
    assert differing <= sensed * 1e-5


def test_edge_poses_agree_too():
    """Headings on the axes and diagonals, poses on cell centres and corners, off the grid's edges."""
    poses = [
        (x, y, theta)
        for x in (0.0, 0.5, 50.0, 99.5, 100.0, -19.0, 119.0)
        for y in (0.0, 50.5, 100.0)
        for theta in (0.0, math.pi / 2, -math.pi / 2, math.pi, -math.pi, math.pi / 4, 3 * math.pi / 4, 7.0)
    ]
    for float_map, exact_map in float_and_exact(PAPER, poses):
        assert np.abs(float_map - exact_map).max() <= 1
        assert (float_map != exact_map).sum() <= 1


def test_the_same_integers_every_time_and_everywhere():
    """A digest of the ticks of 300 seeded poses. Integer arithmetic only after the pose is read, so a
    machine that gets another digest has a broken kernel (written on the 2-core x86-64 VM, 2026-12-02)."""
    kernel = exact_kernel_of(PAPER)
    digest = hashlib.sha256()
    for x, y, theta in random_poses(300, seed=11):
        row0, col0, ticks = event_ticks(kernel, x, y, theta)
        digest.update(np.array([row0, col0, *ticks.shape], dtype="<i8").tobytes() + ticks.astype("<i8").tobytes())
    assert digest.hexdigest()[:16] == GOLDEN_DIGEST


GOLDEN_DIGEST = "75119b8f21ef5a34"


def test_the_window_holds_every_cell_within_range():
    kernel = exact_kernel_of(PAPER)
    row0, row1, col0, col1 = event_window(kernel, 50.2, 60.7)
    assert (row0, row1, col0, col1) == (41, 81, 30, 70)  # centre rows 41.5 .. 80.5 lie within 20 of 60.7, etc.
    assert event_window(kernel, -30.0, 50.0)[2:] == (0, 0)  # out of reach of the grid: empty


def test_scenarios_the_integers_cannot_hold_are_refused():
    with pytest.raises(ValueError, match="2\\^20 units"):
        exact_kernel(10, 10, 1.0, 5e6, 0.5, 1.0, 0.1)
    assert exact_kernel_of(PAPER.with_overrides(range=3e6)) is None


@pytest.mark.parametrize(("sensing_range", "cell"), [(150.0, 1.0), (1000.0, 8.0)])
def test_long_ranges_keep_every_product_in_int64(sensing_range, cell):
    """The window's coordinates scale with R: the kernel's fixed point shrinks so nothing wraps."""
    side = 3.0 * sensing_range
    scenario = PAPER.with_overrides(range=sensing_range, cell=cell, domain=(side, side))
    sensed = differing = 0
    for float_map, exact_map in float_and_exact(scenario, random_poses(150, seed=9, low=0.0, high=side)):
        sensed += int(((float_map > 0) | (exact_map > 0)).sum())
        differing += int((float_map != exact_map).sum())
    assert sensed > 100_000 and differing <= sensed * 1e-5
