"""model.physics.base: the base's parameters over the Burger's proportions, and its wheels' kinematics."""

import math

from hypothesis import given
from hypothesis import strategies as st

from model.physics.base import base_of, wheel_speeds
from model.scenario import validate


def test_the_defaults_are_a_burger_scaled_to_the_scenario():
    burger = base_of(validate({"robot_radius": 0.105, "k_v": 0.22, "physics": "mujoco"}))
    assert math.isclose(burger.wheel_radius, 0.033, rel_tol=0.02)
    assert math.isclose(burger.wheel_separation, 0.160, rel_tol=0.01)
    assert math.isclose(burger.acceleration, 2.5, rel_tol=0.04) and burger.mass == 1.0
    assert math.isclose(burger.wheel_torque, 0.5 * 1.0 * burger.acceleration * burger.wheel_radius)
    given_mass = base_of(validate({"robot_radius": 0.105, "physics": "mujoco", "robot": {"mass": 3.0}}))
    assert given_mass.mass == 3.0 and given_mass.wheel_radius == burger.wheel_radius


@given(st.floats(-2.0, 2.0), st.floats(-5.0, 5.0))
def test_wheel_speeds_drive_the_unicycles_command(v, omega):
    """A rim speed of v ∓ ω b/2 each side: the wheels' mean is v, their difference over b is ω (eq. 1)."""
    base = base_of(validate({"robot_radius": 0.3, "physics": "mujoco"}))
    left, right = wheel_speeds(v, omega, base)
    assert math.isclose(base.wheel_radius * (left + right) / 2.0, v, abs_tol=1e-9)
    assert math.isclose(base.wheel_radius * (right - left) / base.wheel_separation, omega, abs_tol=1e-9)
