"""simulator.bases: the bases anicov sim plays, stepped alone (no bus)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model.parameters import starting_poses
from model.scenario import validate
from simulator.bases import NANOSECONDS, SimulatedBases

ROOM = {
    "domain": [12.0, 8.0], "cell": 1.0, "range": 3.0, "robot_radius": 0.3, "agents": 2, "seed": 1,
    "physics": "mujoco", "controller": "anicov",
}  # fmt: skip
NOISE = {
    "odometry_per_metre": 0.01, "localiser_sigma": 0.05, "localiser_heading_deg": 2.0, "localiser_rate": 5.0,
    "localiser_latency": 0.2,
}  # fmt: skip
"""A fix every 2 periods (5 Hz at dt 0.1), arriving 2 periods after the instant it measured."""


def test_without_noise_the_odometry_is_the_true_pose_in_the_map_frame_stamped_in_simulated_time():
    scenario = validate({**ROOM, "seconds_per_unit": 0.5, "metres_per_unit": 2.0})
    bases = SimulatedBases(scenario)
    first = bases.readings()
    assert [reading.stamp_ns for reading in first] == [0, 0] and not bases.localiser
    start = starting_poses(scenario)
    for reading, pose in zip(first, start, strict=True):
        assert reading.odometry == pytest.approx((2.0 * pose[0], 2.0 * pose[1], pose[2]), abs=1e-9)  # metres
        assert reading.fixes == ()
    bases.command(0, 0.8, 0.0)  # 0.8 m/s = 0.2 units per time unit at 2 m / unit, 0.5 s / unit
    for _ in range(10):
        readings = bases.advance()
    assert bases.step == 10 and readings[0].stamp_ns == round(10 * 0.1 * 0.5 * NANOSECONDS)
    truth = bases.team.truth
    assert readings[0].odometry == pytest.approx((2.0 * truth[0, 0], 2.0 * truth[0, 1], truth[0, 2]))
    assert readings[0].velocity == pytest.approx((0.8, 0.0))
    moved = math.hypot(*(truth[0, :2] - start[0, :2]))
    assert 0.1 < moved <= 0.2 * 1.0 + 1e-6  # 1 time unit at 0.2 units per unit, less what accelerating costs
    assert math.hypot(*(truth[1, :2] - start[1, :2])) < 1e-3  # the other base was told nothing


def test_with_noise_odometry_drifts_and_the_localisers_fixes_arrive_late_stamped_when_measured():
    scenario = validate({**ROOM, "noise": NOISE})
    bases = SimulatedBases(scenario)
    assert bases.localiser
    first = bases.readings()
    assert [fix[0] for fix in first[0].fixes] == [0]  # the start pose, as an operator gives AMCL its first
    assert first[0].fixes[0][1] == pytest.approx(first[0].odometry)
    assert first[0].start and first == bases.readings()  # exact, and so each time it is sent again for a late driver
    bases.command(0, 0.2, 0.1)
    bases.command(1, 0.2, -0.1)
    arrivals = {}
    for _ in range(12):
        readings = bases.advance()
        arrivals[bases.step] = [stamp for stamp, _ in readings[0].fixes]
        assert not readings[0].start  # the localiser's own fixes: sent with its σ
    period = round(0.1 * NANOSECONDS)
    # Measured at steps 2, 4, 6, ...; each handed out 2 periods later, stamped with the instant it measured.
    assert arrivals[4] == [2 * period] and arrivals[6] == [4 * period] and arrivals[12] == [10 * period]
    assert arrivals[3] == arrivals[5] == []
    drift = np.hypot(*(bases.odometry[:, :2] - bases.team.truth[:, :2]).T)
    assert 0.0 < drift.max() < 0.05  # 1 % per unit over about 0.24 units


def test_the_truths_map_takes_what_the_cameras_see_until_the_run_is_declared_over():
    bases = SimulatedBases(validate(ROOM))
    bases.advance()
    seen = bases.team.true_map.coverage.sum()
    assert seen > 0
    bases.sensing = False
    bases.advance()
    assert bases.team.true_map.coverage.sum() == seen
    figures = bases.figures()
    assert figures["simulated_steps"] == 2 and figures["physical_contacts"] == 0
    assert figures["true_coverage"] == 0.0 and figures["true_cells_short"] == 12 * 8  # no cell at Λ* after 0.1
