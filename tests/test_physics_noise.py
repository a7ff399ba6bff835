"""model.physics.noise: odometry that drifts, late and noisy localiser fixes, late commands; all seeded."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from model.physics.noise import (
    Belief,
    CommandDelay,
    Noise,
    fix_gains,
    fused,
    in_own_frame,
    moved_by,
    noise_of,
    predicted_variance,
)
from model.scenario import validate
from model.scenario.physics_keys import COVER_MARGIN


def true_path(periods: int = 200) -> list[np.ndarray]:
    """Two robots' true poses, period by period: one drives a circle, one a straight line."""
    poses, out = np.array([[1.0, 1.0, 0.0], [5.0, 1.0, math.pi / 2]]), []
    for _ in range(periods):
        poses = moved_by(poses, np.array([[0.05, 0.0, 0.1], [0.04, 0.0, 0.0]]))
        out.append(poses.copy())
    return out


def believed(noise: Noise, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    path = true_path()
    belief = Belief(noise, np.array([[1.0, 1.0, 0.0], [5.0, 1.0, math.pi / 2]]), seed)
    return np.stack([belief.update(truth) for truth in path]), np.stack(path)


def position_errors(noise: Noise, seed: int = 1) -> np.ndarray:
    beliefs, truths = believed(noise, seed)
    return np.hypot(*(beliefs[:, :, :2] - truths[:, :, :2]).transpose(2, 0, 1))


@given(st.floats(-2, 2), st.floats(-2, 2), st.floats(-3, 3), st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1))
def test_a_motion_in_the_robots_own_frame_moves_it_back_where_it_went(x, y, theta, dx, dy, turn):
    before = np.array([[x, y, theta]])
    after = moved_by(before, np.array([[dx, dy, turn]]))
    assert np.allclose(in_own_frame(before, after), [[dx, dy, math.remainder(turn, 2 * math.pi)]], atol=1e-9)


def test_without_noise_the_belief_is_the_truth_and_with_exact_late_fixes_too():
    beliefs, truths = believed(Noise())
    assert np.array_equal(beliefs, truths)
    exact_late = Noise(localiser_period=3, localiser_delay=2)  # fixes without error: the replay is exact
    assert np.abs(position_errors(exact_late)).max() < 1e-9


def test_odometry_drifts_further_the_further_it_goes_and_a_localiser_holds_it_near_the_truth():
    drift = Noise(odometry_per_metre=0.05, odometry_per_radian=0.05)
    drifting = np.mean([position_errors(drift, seed) for seed in range(20)], axis=0).mean(axis=1)
    assert drifting[-20:].mean() > 3.0 * drifting[:20].mean()  # a random walk: grows with distance
    fixed = Noise(odometry_per_metre=0.05, odometry_per_radian=0.05, localiser_sigma=0.05, localiser_period=1,
                  localiser_delay=1)  # fmt: skip
    held = np.mean([position_errors(fixed, seed) for seed in range(20)], axis=0).mean(axis=1)
    assert held[-50:].mean() < 0.15 and held[-50:].mean() < 0.5 * drifting[-50:].mean()


def test_the_same_seed_draws_the_same_noise_and_another_seed_other_noise():
    noise = Noise(odometry_per_metre=0.05, localiser_sigma=0.05, localiser_period=2, localiser_delay=1)
    assert np.array_equal(believed(noise, 4)[0], believed(noise, 4)[0])
    assert not np.array_equal(believed(noise, 4)[0], believed(noise, 5)[0])


def test_commands_arrive_whole_periods_late_and_zero_before_the_first():
    delay = CommandDelay(2, agents=1)
    given = [np.array([[float(k), 0.0]]) for k in range(1, 5)]
    assert [float(delay(command)[0, 0]) for command in given] == [0.0, 0.0, 1.0, 2.0]


def test_the_noise_table_in_whole_control_periods():
    scenario = validate({
        "robot_radius": 0.3, "physics": "mujoco",
        "noise": {"localiser_rate": 10.0, "localiser_latency": 0.1, "command_latency": 0.2, "localiser_heading_deg": 2},
    })  # fmt: skip
    noise = noise_of(scenario)
    assert (noise.localiser_period, noise.localiser_delay, noise.command_delay) == (1, 1, 2)
    assert math.isclose(noise.localiser_heading, math.radians(2.0)) and not noise.none
    assert noise.cover_margin == COVER_MARGIN  # with noise the team over-covers its own map by default
    assert noise_of(validate({})).none and noise_of(validate({})).cover_margin == 0.0
    exact = validate({"robot_radius": 0.3, "physics": "mujoco", "noise": {"localiser_sigma": 0.05, "cover_margin": 0}})
    assert noise_of(exact).cover_margin == 0.0


def test_a_fix_moves_the_belief_by_the_kalman_gain_whole_where_it_is_exact_not_at_all_where_the_belief_is():
    noise = Noise(localiser_sigma=0.1, localiser_heading=0.02)
    variance = np.array([[0.01, 0.0004], [0.0, 0.0]])
    gains = fix_gains(variance, noise)
    assert np.allclose(gains, [[0.5, 0.5], [0.0, 0.0]])  # P / (P + σ²); a belief known exactly keeps it
    assert np.array_equal(fix_gains(variance, Noise()), np.ones((2, 2)))  # an exact fix replaces it
    moved = fused(np.array([[0.0, 0.0, 3.1]]), np.array([[1.0, -2.0, -3.1]]), np.array([[0.5, 0.5]]))
    assert np.allclose(moved, [[0.5, -1.0, math.pi]])  # the heading the short way round, across ±π


def test_the_belief_s_variance_grows_with_the_way_travelled_and_turned():
    noise = Noise(odometry_per_metre=0.1, odometry_per_radian=0.2)
    grown = predicted_variance(np.array([[0.0, 0.01]]), np.array([[0.3, 0.1, -0.5]]), noise)
    assert np.allclose(grown, [[0.01 * 0.4 + 0.4**2 * 0.01, 0.01 + 0.04 * 0.5]])
    assert np.array_equal(predicted_variance(np.zeros((1, 2)), np.zeros((1, 3)), noise), np.zeros((1, 2)))


def test_a_robot_standing_still_holds_its_belief_still_where_a_fix_replacing_it_jumped_by_sigma():
    """At a station a robot faces bearings toward a carrot a few σ away: a belief that jumps by σ at every fix
    swings its heading (docs/physics.md)."""
    noise = Noise(odometry_per_metre=0.01, odometry_per_radian=0.01, localiser_sigma=0.05, localiser_period=1,
                  localiser_delay=1)  # fmt: skip
    start = np.array([[1.0, 1.0, 0.0]])
    belief = Belief(noise, start, seed=3)
    for _ in range(50):  # it drives, so the belief has some doubt to take fixes with
        start = moved_by(start, np.array([[0.1, 0.0, 0.0]]))
        belief.update(start)
    standing = np.stack([belief.update(start)[0, :2] for _ in range(100)])
    jumps = np.hypot(*np.diff(standing, axis=0).T)
    assert jumps.max() < 0.2 * noise.localiser_sigma
    assert np.hypot(*(standing[-1] - start[0, :2])) < 3.0 * noise.localiser_sigma
