"""protocol.ros2.frames: quaternions, map ← odom, scenario units."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from protocol.ros2.frames import ScenarioFrame, compose, invert, scale_into, yaw_of_quaternion

angles = st.floats(-math.pi + 1e-6, math.pi, allow_nan=False)
coordinates = st.floats(-1e3, 1e3, allow_nan=False)


@given(angles)
def test_yaw_of_a_rotation_about_z_is_its_angle(theta):
    assert yaw_of_quaternion(0.0, 0.0, math.sin(theta / 2), math.cos(theta / 2)) == pytest.approx(theta, abs=1e-9)


def test_yaw_ignores_roll_of_a_flat_robot_turned_upside_down_as_ros_does():
    # A rotation of π about x (roll) has no yaw; ZYX Euler yaw of (1, 0, 0, 0) is 0.
    assert yaw_of_quaternion(1.0, 0.0, 0.0, 0.0) == pytest.approx(0.0)


def test_compose_places_odometry_in_the_map_frame():
    # odom's origin at (2, 1) in the map, turned 90°: 1 m ahead in odom is 1 m along map y.
    x, y, theta = compose((2.0, 1.0, math.pi / 2), (1.0, 0.0, 0.0))
    assert (x, y, theta) == pytest.approx((2.0, 2.0, math.pi / 2))


@given(coordinates, coordinates, angles, coordinates, coordinates, angles)
def test_compose_adds_headings_and_inverts(ox, oy, ot, x, y, t):
    assert compose((0.0, 0.0, 0.0), (x, y, t)) == pytest.approx((x, y, t), abs=1e-9)
    heading = compose((ox, oy, ot), (x, y, t))[2]
    assert math.cos(heading - (ot + t)) == pytest.approx(1.0, abs=1e-9)  # ot + t, wrapped
    offset = (ox, oy, ot)
    back_x, back_y, back_t = compose(invert(offset), compose(offset, (x, y, t)))
    assert (back_x, back_y) == pytest.approx((x, y), abs=1e-6)
    assert math.cos(back_t - t) == pytest.approx(1.0, abs=1e-9)  # the same heading: π and -π are one


def test_a_localiser_pose_and_the_odometry_of_that_instant_give_map_from_odom():
    odometry, map_pose = (1.0, 0.0, 0.0), (2.0, 2.0, math.pi / 2)
    offset = compose(map_pose, invert(odometry))
    assert offset == pytest.approx((2.0, 1.0, math.pi / 2))
    assert compose(offset, odometry) == pytest.approx(map_pose)


@given(coordinates, coordinates, st.sampled_from([0.0, 0.5, -2.0]))
def test_map_and_scenario_frames_are_inverse(x, y, yaw):
    frame = ScenarioFrame((-3.5, 12.0), metres_per_unit=0.05, seconds_per_unit=0.2, yaw=yaw)
    mx, my = frame.to_map(x, y)
    assert frame.to_scenario((mx, my, 0.3 + yaw)) == pytest.approx((x, y, 0.3), abs=1e-6)


def test_a_turned_map_turns_the_scenario_s_axes():
    # A map whose origin has a yaw of 90°: the scenario's x axis is the map frame's y axis.
    frame = ScenarioFrame((1.0, 2.0), yaw=math.pi / 2)
    assert frame.to_map(3.0, 0.0) == pytest.approx((1.0, 5.0))
    assert frame.to_scenario((1.0, 5.0, math.pi / 2)) == pytest.approx((3.0, 0.0, 0.0))


def test_velocities_scale_by_the_units():
    frame = ScenarioFrame(metres_per_unit=0.05, seconds_per_unit=0.1)
    # 1 unit per time unit is 0.05 m per 0.1 s; 1 rad per time unit is 10 rad/s.
    assert frame.to_ros_velocity(1.0, 1.0) == pytest.approx((0.5, 10.0))
    assert frame.to_scenario_velocity(0.5, 10.0) == pytest.approx((1.0, 1.0))


speeds = st.floats(-100, 100, allow_nan=False)


@given(speeds, speeds)
def test_scaling_into_bounds_keeps_the_curvature_and_the_bounds(v, omega):
    scaled_v, scaled_omega = scale_into(v, omega, 1.0, math.pi)
    assert abs(scaled_v) <= 1.0 + 1e-12 and abs(scaled_omega) <= math.pi + 1e-12
    assert scaled_v * omega == pytest.approx(scaled_omega * v, abs=1e-9)  # same ω / v
    if abs(v) <= 1.0 and abs(omega) <= math.pi:
        assert (scaled_v, scaled_omega) == (v, omega)
    assert scale_into(4.0, 1.0, 2.0, math.inf) == (2.0, 0.5)
