"""The safety figures of a run (model.safety.safety_record)."""

from __future__ import annotations

import math

import numpy as np

from model.safety.safety import DEADLOCK_FOUND, DEADLOCK_RESOLVED, FILTER_CHANGED, RAN_LATE
from model.safety.safety_record import fill_unheard, min_clearance, min_separation, safety_figures
from model.scenario import validate
from model.world.ground import open_ground
from model.world.world import world_of


def test_robots_crossing_between_two_steps_are_caught_on_the_chord():
    # Robot 0 goes from x = 0 to 4, robot 1 from 4 to 0, 0.1 apart in y: at the steps 4 apart, mid-way 0.1.
    positions = np.array([[[0.0, 0.0], [4.0, 0.1]], [[4.0, 0.0], [0.0, 0.1]]])
    assert math.isclose(min_separation(positions), 0.1)


def test_separation_needs_two_robots_and_skips_what_was_never_heard():
    assert min_separation(np.zeros((5, 1, 2))) is None
    positions = np.array([[[0.0, 0.0], [3.0, 0.0]], [[np.nan, np.nan], [3.0, 0.0]], [[2.0, 0.0], [3.0, 0.0]]])
    filled = fill_unheard(positions)
    assert filled[1, 0].tolist() == [1.0, 0.0]  # interpolated between the heard steps
    assert math.isclose(min_separation(positions), 1.0)


def test_clearance_is_the_distance_to_the_nearest_wall():
    scenario = validate(
        {"domain": [20.0, 20.0], "robot_radius": 0.5, "obstacles": [[[10, 0], [11, 0], [11, 20], [10, 20]]]}
    )
    ground = world_of(scenario).ground
    positions = np.array([[[8.0, 5.0]], [[9.25, 5.0]], [[3.0, 5.0]]])
    assert math.isclose(min_clearance(positions, ground, 1.0), 0.75)
    assert min_clearance(positions, open_ground(), 1.0) is None


def test_figures_count_the_flags():
    positions = np.array([[[0.0, 0.0], [5.0, 0.0]]] * 4)
    flags = np.array(
        [[FILTER_CHANGED, 0], [DEADLOCK_FOUND | FILTER_CHANGED, 0], [DEADLOCK_RESOLVED, RAN_LATE]], dtype=np.uint8
    )
    figures = safety_figures(positions, flags, open_ground(), 1.0)
    assert figures["filter_active_fraction"] == 2 / 6
    assert (figures["deadlocks"], figures["deadlocks_resolved"], figures["late_steps"]) == (1, 1, 1)
    assert figures["min_separation"] == 5.0 and figures["min_clearance"] is None


def test_realtime_separation_is_taken_on_the_wall_clock():
    from model.safety.safety_record import min_separation_in_time

    # Robot 0 moves along y = 0 from x = 0 to 10 over t 0..10; robot 1 stands at (5, 1) but was heard at
    # other instants: on the wall clock they pass 1 apart at t = 5.
    first = np.array([[0.0, 0.0, 0.0], [10.0, 10.0, 0.0]])
    second = np.array([[0.5, 5.0, 1.0], [3.7, 5.0, 1.0], [9.5, 5.0, 1.0]])
    assert math.isclose(min_separation_in_time({0: first, 1: second}), 1.0)
    assert min_separation_in_time({0: first}) is None
