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
    assert result.completed and result.physics is not None
    assert {key: result.physics[key] for key in ("physical_contacts", "robot_contacts", "wall_contacts")} == {
        "physical_contacts": 0, "robot_contacts": 0, "wall_contacts": 0,
    }  # fmt: skip
    summary = summary_of(result)
    assert summary["physical_contacts"] == 0 and summary["scenario"]["physics"] == "mujoco"
    kinematic = run_scenario(scenario.with_overrides(physics="kinematic"))
    # The world's poses are not eq. 1's (the wheels accelerate within the base's torque), and the run is
    # about as long. Measured with anicov's stares planned beside its hops: 176.4 against 149.9 time units for
    # this seed (+18 %; at 1.0 Λ* 178.4 against 147.2, and seeds 0, 1, 3, 4 and 5 +5 %, +3 %, +5 %, +2 % and
    # +8 %; the goal of 15 % is on the study's means, docs/physics.md). Before the hops were counted:
    # 160.2 against 158.2.
    assert result.trace[1:, :, :3].tobytes() != kinematic.trace[1:, :, :3].tobytes()
    assert abs(result.completion_time - kinematic.completion_time) <= 0.25 * kinematic.completion_time
    assert "physical_contacts" not in summary_of(kinematic) and kinematic.physics is None


def test_a_physics_run_repeats_bit_for_bit(physical):
    scenario, result = physical
    again = run_scenario(scenario)
    assert again.trace.tobytes() == result.trace.tobytes()
    assert np.array_equal(again.errors, result.errors)


NOISE = {
    "odometry_per_metre": 0.01, "odometry_per_radian": 0.01, "localiser_sigma": 0.05, "localiser_heading_deg": 2.0,
    "localiser_rate": 10.0, "localiser_latency": 0.1, "command_latency": 0.1,
}  # fmt: skip
"""The issue's noise: σ = 0.05 and 2° at 10 Hz, 0.1 late; commands 0.1 late; odometry drifting 1 %."""


def test_without_noise_the_truth_is_what_the_team_believes(physical):
    _, result = physical
    assert result.true_poses is not None and result.true_poses.shape == result.trace[:, :, :3].shape
    assert np.array_equal(result.true_poses, result.trace[:, :, :3])
    assert result.physics["true_coverage"] == 1.0 and result.physics["true_cells_short"] == 0


def test_with_noise_the_truth_is_kept_beside_the_belief_and_written_out(tmp_path):
    """The paper's law: it believes it covered everything; the cameras' true poses may have covered a little
    less (measured, seed 2: with the cover margin 0 of 372 cells short, without it 3, 99.2 %)."""
    from logger.recording import record_result
    from logger.replay import summarise_recording
    from runtime.rundir import write_run_directory

    scenario = validate({**ROOMS, "physics": "mujoco", "noise": NOISE})
    result = run_scenario(scenario)
    assert result.completed and result.physics["physical_contacts"] == 0
    errors = np.hypot(*(result.true_poses[:, :, :2] - result.trace[:, :, :2]).transpose(2, 0, 1))
    assert 0.0 < errors.mean() < 0.2  # the belief is off the truth by about the localiser's σ
    assert 0.995 <= result.physics["true_coverage"] <= 1.0  # the goal, with the default cover margin
    assert result.physics["true_cells_short"] == round((1.0 - result.physics["true_coverage"]) * 372)
    summary = write_run_directory(result, tmp_path)
    assert summary["true_coverage"] == result.physics["true_coverage"]
    assert (tmp_path / "truth.png").stat().st_size > 10_000  # belief against truth, drawn
    record_result(result, tmp_path / "recording.rrd", recording_id="truth-test")
    entities = summarise_recording(tmp_path / "recording.rrd", load_maps=False).entities
    assert {f"/world/truth/{i}/position" for i in range(4)} | {f"/truth/{i}/error" for i in range(4)} <= entities
    lines = (tmp_path / "truth.csv").read_text().splitlines()
    assert lines[0] == "t,agent,x,y,theta,x_believed,y_believed,theta_believed"
    assert len(lines) == 1 + len(result.trace) * 4  # (that the noise repeats by its seed: test_physics_noise)


def test_the_shipped_two_rooms_are_the_ones_measured_here():
    """scenarios/physics-rooms.toml (the README's physics command) is this file's rooms with the issue's noise."""
    from pathlib import Path

    from model.scenario import load_scenario

    shipped = load_scenario(Path(__file__).resolve().parent.parent / "scenarios" / "physics-rooms.toml")
    assert shipped == validate({**ROOMS, "controller": "anicov", "physics": "mujoco", "noise": NOISE})


def test_the_clearance_reserve_keeps_two_robots_apart_with_a_poor_localiser_and_late_commands():
    """Issue 37, item 5: two robots start facing each other in a corridor, their localiser off by σ = 0.1, their
    odometry drifting 1 % (with exact odometry the fused belief would take nothing from the fixes and be the
    truth) and their commands a whole second late (10 periods). The reserve (3 σ of the fused belief + k_v × 1.0
    + k_v² / 2a = 1.102 each, beyond s) keeps their true bodies apart (the least gap of their true centres 1.958,
    complete at 309.0); with ``clearance_reserve = 0`` the same run has robot contacts (3, complete at 262.4).
    Before the filter asked a robot inside a teammate's margin only not to come nearer when nothing else was
    safe, both stood for good from t = 210 here."""
    scenario = validate({
        "domain": [20.0, 8.0], "cell": 1.0, "range": 5.0, "robot_radius": 0.4, "agents": 2, "seed": 0,
        "safety_range": 6.0, "physics": "mujoco", "max_time": 600.0, "initial_poses": [[1.5, 4.0, 0.0], [18.5, 4.0, 180.0]],
        "noise": {"localiser_sigma": 0.1, "localiser_heading_deg": 2.0, "localiser_rate": 10.0,
                  "localiser_latency": 0.1, "command_latency": 1.0, "odometry_per_metre": 0.01,
                  "odometry_per_radian": 0.01, "cover_margin": 0.05},  # the run measured (the default is now 0.04)
    })  # fmt: skip
    result = run_scenario(scenario)
    assert result.completed and result.physics is not None and result.true_poses is not None
    assert result.physics["physical_contacts"] == 0
    gaps = np.linalg.norm(result.true_poses[:, 0, :2] - result.true_poses[:, 1, :2], axis=1)
    assert gaps.min() > 2.0 * scenario.robot_radius + scenario.safety_margin
    bare = run_scenario(scenario.with_overrides(noise={**dict(scenario.noise), "clearance_reserve": 0.0}))
    assert bare.physics is not None and bare.physics["robot_contacts"] > 0
