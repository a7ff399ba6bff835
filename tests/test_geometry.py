import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from model.paper.geometry import square_gap2, wedge_bounds, wedge_cell_range, wrap_angle

angles = st.floats(-50.0, 50.0, allow_nan=False)


@given(angles)
def test_wrap_angle_lands_in_half_open_interval_and_keeps_direction(angle):
    wrapped = wrap_angle(angle)
    assert -math.pi < wrapped <= math.pi + 1e-12
    assert math.isclose(math.cos(wrapped), math.cos(angle), abs_tol=1e-9)
    assert math.isclose(math.sin(wrapped), math.sin(angle), abs_tol=1e-9)


def test_wrap_angle_maps_minus_pi_to_pi():
    assert wrap_angle(-math.pi) == math.pi


@given(st.floats(-3.2, 3.2), st.floats(0.05, 1.5))
def test_wedge_bounds_contain_sampled_wedge_points(theta, half_angle):
    x_min, x_max, y_min, y_max = wedge_bounds(10.0, -5.0, theta, 20.0, half_angle)
    for r in np.linspace(0.0, 20.0, 9):
        for phi in np.linspace(theta - half_angle, theta + half_angle, 15):
            px, py = 10.0 + r * math.cos(phi), -5.0 + r * math.sin(phi)
            assert x_min - 1e-9 <= px <= x_max + 1e-9
            assert y_min - 1e-9 <= py <= y_max + 1e-9


def test_wedge_cell_range_covers_cell_centres_in_box():
    row0, row1, col0, col1 = wedge_cell_range(50.3, 50.7, 0.0, 20.0, 0.5, 1.0)
    # Heading +x: the box starts at the apex column (x = 50.3 → first centre 50.5) and ends at 70.3.
    assert col0 == 50 and col1 == 70
    # Half angle 0.5 rad: y spans 50.7 ± 20·sin 0.5 = [41.11, 60.29] → centres 41.5 .. 59.5.
    assert row0 == 41 and row1 == 60


@given(st.floats(-30.0, 30.0), st.floats(-30.0, 30.0), st.floats(0.1, 5.0))
def test_square_gap2_is_the_squared_distance_to_the_nearest_point_of_the_square(left, bottom, side):
    nearest_x = min(max(0.0, left), left + side)  # the origin clamped into the square
    nearest_y = min(max(0.0, bottom), bottom + side)
    assert math.isclose(square_gap2(left, bottom, side), nearest_x**2 + nearest_y**2, rel_tol=1e-12, abs_tol=1e-12)
    assert square_gap2(-side / 2.0, -side / 2.0, side) == 0.0  # the origin inside
