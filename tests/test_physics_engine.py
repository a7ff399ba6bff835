"""anicov.physics_engine: a whole team in a MuJoCo world, in process (issue 37, item 1)."""

from __future__ import annotations

import numpy as np
import pytest

from anicov.engine import run_scenario
from model.scenario import validate
from runtime.rundir import summary_of

ROOMS = {
    "domain": [24.0, 16.0], "cell": 1.0, "range": 5.0, "robot_radius": 0.4, "occlusion": True, "agents": 4, "seed": 2,
    "obstacles": [[[12.0, 0.0], [13.0, 0.0], [13.0, 6.0], [12.0, 6.0]],
                  [[12.0, 10.0], [13.0, 10.0], [13.0, 16.0], [12.0, 16.0]]],
}  # fmt: skip
"""Two rooms joined by a door, four robots with bodies and the safety filter."""


@pytest.fixture(scope="module")
def physical():
    scenario = validate({**ROOMS, "controller": "anicov", "physics": "mujoco"})
    return scenario, run_scenario(scenario)


def test_a_team_with_the_filter_completes_in_the_physics_world_without_a_contact(physical):
    scenario, result = physical
    assert result.completed and result.physics == {"physical_contacts": 0, "robot_contacts": 0, "wall_contacts": 0}
    summary = summary_of(result)
    assert summary["physical_contacts"] == 0 and summary["scenario"]["physics"] == "mujoco"
    kinematic = run_scenario(scenario.with_overrides(physics="kinematic"))
    # The world's poses are not eq. 1's (the wheels accelerate within the base's torque), and the run is
    # about as long: measured 161.9 against 158.2 time units.
    assert result.trace[1:, :, :3].tobytes() != kinematic.trace[1:, :, :3].tobytes()
    assert abs(result.completion_time - kinematic.completion_time) <= 0.15 * kinematic.completion_time
    assert "physical_contacts" not in summary_of(kinematic) and kinematic.physics is None


def test_a_physics_run_repeats_bit_for_bit(physical):
    scenario, result = physical
    again = run_scenario(scenario)
    assert again.trace.tobytes() == result.trace.tobytes()
    assert np.array_equal(again.errors, result.errors)
