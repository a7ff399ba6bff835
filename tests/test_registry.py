"""model.controllers.registry: controllers by name, an installed package's by entry point, a user's own by
import path or file; every way a name can be wrong is an error that names it; a scenario asks the controller
what it supports."""

from __future__ import annotations

import sys
import textwrap

import pytest

from model.controllers import BUILT_IN, Controller, ControllerError, canonical_name, controller_of, law_of
from model.controllers.registry import ENTRY_POINT_GROUP, controller_class
from model.scenario import ScenarioError, validate
from model.scenario.physics_keys import sure_doubt_of

GOOD = """
from model.controllers import Controller

class Still(Controller):
    name = "still"

    def command(self, view):
        return 0.0, 0.0

NOT_A_CONTROLLER = 42

class NeverPlans(Controller):
    name = "never-plans"

    def command(self, view):
        return 0.0, 0.0

    def plan_steps(self, scenario):
        return 0

class Grumpy(Controller):
    name = "grumpy"

    def __init__(self):
        raise RuntimeError("will not start")
"""


@pytest.fixture
def plugin_dir(tmp_path, monkeypatch):
    """A folder on sys.path with a plug-in module, and an installed distribution declaring it as an entry
    point of anicov.controllers (a .dist-info, as pip would install it)."""
    name = f"plugin_{tmp_path.name.replace('-', '_')}"
    (tmp_path / f"{name}.py").write_text(textwrap.dedent(GOOD))
    info = tmp_path / "anicov_test_plugin-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: anicov-test-plugin\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(f"[{ENTRY_POINT_GROUP}]\nstill-installed = {name}:Still\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield tmp_path, name
    sys.modules.pop(name, None)
    controller_class.cache_clear()


def test_every_built_in_name_loads_its_controller_and_best_is_anicov():
    assert set(BUILT_IN) == {"paper", "paper-literal", "paper-eq16", "zigzag", "boustrophedon", "anicov"}
    for name, controller in BUILT_IN.items():
        assert controller.name == name and issubclass(controller, Controller)
    assert canonical_name("best") == "anicov"
    assert validate({"controller": "best"}).controller == "anicov"


def test_a_controller_loads_by_module_path_by_file_and_by_entry_point(plugin_dir):
    folder, module = plugin_dir
    assert controller_class(f"{module}:Still").name == "still"
    by_file = canonical_name(f"{module}.py:Still", base=folder)
    assert by_file == f"{(folder / module).resolve()}.py:Still"
    assert controller_class(by_file).name == "still"
    assert controller_class("still-installed").name == "still"
    scenario = validate({"controller": f"{module}.py:Still"}, folder)
    assert scenario.controller == by_file
    assert not controller_of(scenario).compiled and controller_of(validate({})).compiled


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("magic", "expected one of paper, paper-literal, paper-eq16, zigzag, boustrophedon, anicov, best"),
        ("no_such_module_anywhere:Thing", "cannot be loaded: ModuleNotFoundError"),
        ("{module}:Missing", "has no attribute 'Missing'"),
        ("{module}:NOT_A_CONTROLLER", "is 42, not a subclass of model.controllers.interface.Controller"),
        ("nowhere/at/all.py:Thing", "does not exist"),
        (":Thing", "expected module.path:ClassName"),
    ],
)
def test_a_bad_name_is_an_error_that_names_the_controller(plugin_dir, name, message):
    name = name.format(module=plugin_dir[1])
    with pytest.raises(ControllerError, match=message):
        canonical_name(name)
    with pytest.raises(ScenarioError, match="scenario key 'controller'"):
        validate({"controller": name})


def test_a_constructor_that_raises_is_named_when_the_scenario_is_read(plugin_dir):
    with pytest.raises(ScenarioError, match=r"controller '.*:Grumpy': its constructor raised RuntimeError: will not"):
        validate({"controller": f"{plugin_dir[1]}:Grumpy"})


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"controller": "anicov", "robot_radius": 0.3, "stations": False}, "'stations': false flies anicov's"),
        ({"controller": "zigzag", "obstacles": [[[1, 1], [2, 1], [2, 2]]]}, "'zigzag' knows no walls"),
        ({"controller": "zigzag", "planning": "local"}, "'zigzag' plans for the whole team at once"),
        ({"controller": "{module}:Still", "robot_radius": 0.3}, "knows no walls or robot bodies"),
        ({"controller": "{module}:Still", "comm_range": 30.0}, "run the compiled controllers only"),
        (
            {"controller": "{module}:NeverPlans"},
            r"plans every 0 steps \(plan_steps\); expected a whole number of at least 1",
        ),
    ],
)
def test_the_scenario_check_asks_the_controller_what_it_supports(plugin_dir, values, message):
    values = {
        key: value.format(module=plugin_dir[1]) if key == "controller" else value for key, value in values.items()
    }
    with pytest.raises(ScenarioError, match=message):
        validate(values)


def test_the_paper_controllers_support_walls_bodies_and_local_planning():
    for name in ("paper", "paper-literal", "paper-eq16"):
        assert validate({"controller": name, "robot_radius": 0.3, "planning": "local"}).controller == name


@pytest.mark.parametrize("name", ["paper", "anicov"])
def test_the_law_of_a_robot_unsure_of_its_pose_carries_the_scenario_doubt(name):
    body = {"robot_radius": 0.3, "physics": "mujoco", "controller": name}
    noise = {"localiser_sigma": 0.05, "localiser_heading_deg": 2.0}
    exact = validate({**body, "noise": noise})
    sure = validate({**body, "noise": {**noise, "sure_sigmas": 2}})
    assert law_of(controller_of(exact), exact, 100).position_doubt == 0.0
    law = law_of(controller_of(sure), sure, 100)
    assert (law.position_doubt, law.heading_doubt) == pytest.approx(sure_doubt_of(sure))
    assert law._replace(position_doubt=0.0, heading_doubt=0.0) == controller_of(sure).law(sure, 100)
