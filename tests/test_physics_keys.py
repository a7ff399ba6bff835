"""model.scenario.physics_keys: physics = "kinematic" | "mujoco" and the [robot] table, each error naming its key."""

import math

import pytest

from model.scenario import ScenarioError, validate
from model.scenario.physics_keys import cover_margin_of, sure_doubt_of

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
