"""model.controllers.plugin_step: a controller written in Python reads the wedge as the compiled kernel does,
and every command it returns is checked; a bad one is an error naming the controller, the robot and the step."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model.controllers import Controller, RobotView
from model.controllers.plugin_step import PluginCommandError, decide_with
from model.controllers.registry import law_parameters
from model.parameters import coverage_map_of
from model.scenario import validate
from model.step import decide_and_sense, no_look
from model.world.ground import NO_FIELD, open_ground


class Fixed(Controller):
    """Returns whatever it was made with (or raises it)."""

    name = "fixed"

    def __init__(self, answer: object = (0.5, 0.1)) -> None:
        self.answer = answer
        self.seen: list[RobotView] = []

    def command(self, view: RobotView) -> tuple[float, float]:
        self.seen.append(view)
        if isinstance(self.answer, Exception):
            raise self.answer
        return self.answer  # type: ignore[return-value]


def one_step(controller: Controller, step: int = 7):
    scenario = validate({"domain": [30.0, 30.0], "agents": 2})
    grid = coverage_map_of(scenario)
    grid.coverage[10:14, 10:20] = grid.target_ticks  # some covered cells in view
    law = law_parameters(scenario, grid)
    positions = np.array([[12.0, 8.0], [25.0, 25.0]])
    pose = (12.0, 8.0, 1.2)
    outcome = decide_with(
        controller, scenario, step, grid.coverage, pose, (20.0, 20.0), law, open_ground(), positions, 0
    )
    return scenario, grid, law, positions, pose, outcome


def test_the_wedge_is_read_as_the_compiled_kernel_reads_it():
    controller = Fixed()
    _, grid, law, positions, pose, (v, omega, e_omega, row0, col0, ticks) = one_step(controller)
    compiled = decide_and_sense(grid.coverage, *pose, 20.0, 20.0, law, open_ground(), NO_FIELD, positions, 0, no_look())
    assert (v, omega) == (0.5, 0.1)
    assert e_omega == compiled[2] and (row0, col0) == compiled[3:5]
    assert np.array_equal(ticks, compiled[5]) and ticks.sum() > 0
    view = controller.seen[0]
    assert (view.agent, view.step, view.x, view.y, view.theta) == (0, 7, *pose)
    assert (view.objective_x, view.objective_y) == (20.0, 20.0)
    assert view.e_omega == e_omega and view.w_left + view.w_right > 0
    assert view.lack[11, 15] == 0.0 and view.lack[0, 0] == 1.0


def test_the_view_cannot_change_the_map_or_the_positions():
    controller = Fixed()
    one_step(controller)
    view = controller.seen[0]
    with pytest.raises(ValueError, match="read-only"):
        view.coverage[0, 0] = 1
    with pytest.raises(ValueError, match="read-only"):
        view.positions[1, 0] = 0.0


@pytest.mark.parametrize(
    ("answer", "message"),
    [
        ((math.nan, 0.0), r"returned \(v, omega\) = \(nan, 0.0\), expected finite numbers"),
        ((0.0, math.inf), "expected finite numbers"),
        ((1.5, 0.0), r"outside \|v\| <= k_v = 1.0"),
        ((0.0, -3.2), r"\|omega\| <= k_omega pi = 3.14159"),
        ((0.1,), r"returned \(0.1,\), expected \(v, omega\)"),
        ("fast", "expected \\(v, omega\\)"),
        ("12", "returned .12., expected \\(v, omega\\)"),
        (ZeroDivisionError("boom"), "command\\(\\) raised ZeroDivisionError: boom"),
    ],
)
def test_a_bad_command_names_the_controller_the_robot_and_the_step(answer, message):
    with pytest.raises(PluginCommandError, match=r"controller 'paper', robot 0, step 7: .*" + message):
        one_step(Fixed(answer))


def test_commands_at_the_bounds_are_applied():
    for answer in [(1.0, math.pi), (-1.0, -math.pi), (0.0, 0.0)]:
        assert one_step(Fixed(answer))[-1][:2] == answer
