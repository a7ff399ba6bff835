"""model.scenario.physics_keys: physics = "kinematic" | "mujoco" and the [robot] table, each error naming its key."""

import math

import numpy as np
import pytest

from model.paper.dynamics import unicycle_step
from model.parameters import safety_parameters
from model.physics.noise import fix_gains, in_own_frame, noise_of, predicted_variance
from model.scenario import ScenarioError, validate
from model.scenario.physics_keys import (
    belief_sigma_of,
    clearance_reserve_of,
    cover_margin_of,
    safety_margin_of,
    sure_doubt_of,
)
from model.world.world import wall_clearance_of

BODY = {"robot_radius": 0.3}


def test_kinematic_is_the_default_and_leaves_the_scenario_as_it_was():
    scenario = validate({})
    assert scenario.physics == "kinematic" and scenario.robot == ()
    assert "physics" not in scenario.to_dict() and "robot" not in scenario.to_dict()  # summaries unchanged


def test_the_robot_table_is_kept_sorted_and_survives_overrides():
    scenario = validate({**BODY, "physics": "mujoco", "robot": {"mass": 2, "acceleration": 1.5}})
    assert scenario.robot == (("acceleration", 1.5), ("mass", 2.0))
    assert scenario.to_dict()["robot"] == {"acceleration": 1.5, "mass": 2.0}
    assert scenario.with_overrides(agents=2).robot == scenario.robot


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"physics": "ode"}, "scenario key 'physics': expected one of kinematic, mujoco, got 'ode'"),
        ({"physics": "mujoco"}, "'mujoco' simulates robot bodies: expected robot_radius > 0"),
        ({"robot": {"mass": 2.0}}, r"scenario key 'robot': the base's parameters are read by physics = \"mujoco\""),
        ({**BODY, "physics": "mujoco", "robot": {"wheels": 2}}, "unknown scenario key 'robot.wheels'"),
        ({**BODY, "physics": "mujoco", "robot": {"mass": -1}}, "scenario key 'robot.mass': expected a positive"),
        ({**BODY, "physics": "mujoco", "robot": 3}, "scenario key 'robot': expected a table"),
        ({**BODY, "physics": "mujoco", "robot": {"wheel_separation": 0.7}}, "'robot.wheel_separation': expected less"),
        ({**BODY, "physics": "mujoco", "robot": {"wheel_radius": 0.3}}, "'robot.wheel_radius': expected less"),
        ({**BODY, "physics": "mujoco", "planning": "local"}, "'mujoco' runs with planning = \"central\""),
    ],
)
def test_bad_physics_keys_name_the_key(values, message):
    with pytest.raises(ScenarioError, match=message):
        validate(values)


def test_the_sure_rule_doubts_the_pose_by_sure_sigmas_times_the_localiser_sigma():
    noisy = {**BODY, "physics": "mujoco", "noise": {"localiser_sigma": 0.05, "localiser_heading_deg": 2.0}}
    assert sure_doubt_of(validate(noisy)) == (0.0, 0.0)  # the cover margin is the default rule
    sure = validate({**noisy, "noise": {**noisy["noise"], "sure_sigmas": 2}})
    assert sure_doubt_of(sure) == pytest.approx((0.1, math.radians(4.0)))
    assert sure_doubt_of(validate({})) == (0.0, 0.0)
    only_rule = validate({**BODY, "physics": "mujoco", "noise": {"sure_sigmas": 2}})
    assert sure_doubt_of(only_rule) == (0.0, 0.0) and cover_margin_of(only_rule) == 0.0  # a rule is not noise
    with pytest.raises(ScenarioError, match=r"noise\.sure_sigmas': expected a non-negative number"):
        validate({**BODY, "physics": "mujoco", "noise": {"sure_sigmas": -1}})


def test_the_clearance_reserve_takes_the_pose_error_the_late_command_and_the_braking():
    """Issue 37, item 5: 3 σ of the belief + k_v × command_latency + k_v² / 2a beyond safety_margin, for the filter, the
    ground and the planner alike; 0 for kinematic robots; the [noise] table's clearance_reserve if given."""
    assert clearance_reserve_of(validate(BODY)) == 0.0 and safety_margin_of(validate(BODY)) == 0.2
    still = validate({**BODY, "k_v": 2.0, "physics": "mujoco", "robot": {"acceleration": 8.0}})
    assert clearance_reserve_of(still) == pytest.approx(2.0**2 / (2.0 * 8.0))
    fixes = {"localiser_sigma": 0.05, "localiser_rate": 10.0, "odometry_per_metre": 0.01}
    noisy = validate({
        **BODY, "physics": "mujoco", "noise": {**fixes, "command_latency": 0.1, "cover_margin": 0.3},
    })  # fmt: skip
    assert 0.0 < belief_sigma_of(noisy) < 0.05  # the fused belief is surer than one fix
    reserve = 3 * belief_sigma_of(noisy) + 1.0 * 0.1 + 1.0 / (2.0 * 11.0)  # k_v 1, the Burger's acceleration 11 k_v
    assert clearance_reserve_of(noisy) == pytest.approx(reserve)
    assert safety_parameters(noisy).margin == pytest.approx(0.2 + reserve)
    assert safety_parameters(noisy).pair_margin == pytest.approx(0.2 + 2.0 * reserve)  # each robot brings its own
    assert wall_clearance_of(noisy) == pytest.approx(0.3 + 0.2 + reserve)
    given = validate({**BODY, "physics": "mujoco", "noise": {"localiser_sigma": 0.05, "clearance_reserve": 0}})
    assert safety_margin_of(given) == 0.2 and cover_margin_of(given) > 0.0  # a rule, the noise still noise


@pytest.mark.parametrize("rate", [10.0, 2.5])
def test_the_beliefs_sigma_is_the_steady_state_of_the_beliefs_own_variance(rate):
    """belief_sigma_of, in closed form, against model.physics.noise's recursion run to its steady state: a robot
    that drives at k_v and turns at π k_ω every step (eq. 1's step, in its own frame as the odometry counts it),
    a fix every 1 / rate (its variance fused by the Kalman gain), the variance taken just before a fix. A
    latency adds the odometry of that many steps more (the fix replayed), and never takes any away."""
    noise_table = {
        "odometry_per_metre": 0.01, "odometry_per_radian": 0.01, "localiser_sigma": 0.05,
        "localiser_heading_deg": 2.0, "localiser_rate": rate,
    }  # fmt: skip
    scenario = validate({**BODY, "k_omega": 0.9, "physics": "mujoco", "noise": noise_table})
    noise = noise_of(scenario)
    turn = math.pi * scenario.k_omega
    after = np.array([unicycle_step(0.0, 0.0, 0.0, scenario.k_v, turn, scenario.dt)])
    motion = in_own_frame(np.zeros((1, 3)), after)
    variance, before_fix = np.zeros((1, 2)), 0.0
    for step in range(1, 4001):
        variance = predicted_variance(variance, motion, noise)
        if step % noise.localiser_period == 0:
            before_fix = float(variance[0, 0])
            variance = (1.0 - fix_gains(variance, noise)) * variance
    assert belief_sigma_of(scenario) == pytest.approx(math.sqrt(before_fix), rel=1e-6)
    late = scenario.with_overrides(noise={**noise_table, "localiser_latency": 0.3})
    assert belief_sigma_of(late) > belief_sigma_of(scenario)
    assert belief_sigma_of(validate({**BODY, "physics": "mujoco", "noise": {"localiser_sigma": 0.05}})) == 0.0
