import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from model.paper.dynamics import unicycle_step


def test_straight_line():
    assert unicycle_step(1.0, 2.0, 0.0, 1.0, 0.0, 0.5) == (1.5, 2.0, 0.0)


def test_turn_in_place_keeps_position():
    x, y, theta = unicycle_step(1.0, 2.0, 0.0, 0.0, math.pi / 2, 1.0)
    assert (x, y) == (1.0, 2.0)
    assert theta == pytest.approx(math.pi / 2)


def test_quarter_circle_arc():
    # v = ω = 1 for π/2: a quarter of the unit circle from (0, 0) heading +x ends at (1, 1).
    x, y, theta = unicycle_step(0.0, 0.0, 0.0, 1.0, 1.0, math.pi / 2)
    assert (x, y, theta) == pytest.approx((1.0, 1.0, math.pi / 2))


@given(st.floats(-1, 1), st.floats(-3.2, 3.2), st.floats(-math.pi, math.pi))
def test_euler_agrees_for_small_steps(v, omega, theta):
    dt = 1e-4
    x, y, _new_theta = unicycle_step(0.0, 0.0, theta, v, omega, dt)
    assert x == pytest.approx(v * math.cos(theta) * dt, abs=1e-7)
    assert y == pytest.approx(v * math.sin(theta) * dt, abs=1e-7)
    assert math.hypot(x, y) <= abs(v) * dt + 1e-12
