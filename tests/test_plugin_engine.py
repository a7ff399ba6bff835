"""anicov.plugin_engine: a controller written in Python runs in the engine as a compiled one does. The paper's
law written as a plug-in gives the compiled law's run exactly; the example of examples/ completes; a plug-in
that fails mid-run stops the run with an error naming it."""

from __future__ import annotations

import numpy as np
import pytest

from anicov.engine import run_scenario
from model.controllers import Controller, RobotView
from model.controllers.plugin_step import PluginCommandError
from model.scenario import validate
from tests.teamrun import ROOT


class FailsAtStep(Controller):
    name = "fails-at-step-40"

    def command(self, view: RobotView) -> tuple[float, float]:
        if view.step == 40 and view.agent == 1:
            return float("nan"), 0.0
        return 0.5, 0.0


def scenario_with(controller: str, **keys):
    return validate({"domain": [40.0, 40.0], "agents": 2, "seed": 3, "controller": controller, **keys})


def test_the_papers_law_as_a_plug_in_gives_the_compiled_run_exactly():
    compiled = run_scenario(scenario_with("paper"))
    plugin = run_scenario(scenario_with(f"{ROOT / 'examples' / 'paper_in_python.py'}:PaperInPython"))
    assert compiled.completed and plugin.completed
    assert plugin.steps == compiled.steps
    assert np.array_equal(plugin.trace, compiled.trace)
    assert np.array_equal(plugin.errors, compiled.errors)


def test_the_example_controller_from_outside_the_package_completes():
    scenario = scenario_with(str(ROOT / "examples" / "nearest_uncovered.py") + ":NearestUncovered", agents=3)
    result = run_scenario(scenario)
    assert result.completed and result.final_lack.max() == 0
    speeds = np.abs(result.trace[:-1, :, 3])
    assert speeds.max() <= scenario.k_v and speeds.sum() > 0
    # It keeps each robot's target between steps; a second run in the same process (a sweep's worker) gets a
    # new controller, so nothing of the first run leaks into it.
    assert np.array_equal(run_scenario(scenario).trace, result.trace)


def test_a_plug_in_that_fails_mid_run_stops_it_naming_the_controller_the_robot_and_the_step():
    with pytest.raises(
        PluginCommandError, match=r"controller 'tests.test_plugin_engine:FailsAtStep', robot 1, step 40"
    ):
        run_scenario(scenario_with("tests.test_plugin_engine:FailsAtStep"))
