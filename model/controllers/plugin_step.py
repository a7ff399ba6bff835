"""One robot's step for a controller written in Python (:meth:`model.controllers.interface.Controller.command`):
the same sensing as the compiled kernel (:func:`model.step.read_wedge`, eq. 2–3, 6, 9), then the controller's
(v, ω), checked. The engine and the agent process both call :func:`decide_with`, so a team of plug-in robots
over Zenoh in lockstep equals the engine byte for byte."""

from __future__ import annotations

import math

import numpy as np

from model.controllers.interface import Controller, RobotView, command_bounds
from model.scenario import Scenario
from model.step import LawParameters, read_wedge
from model.world.ground import Ground
from model.world.occlusion import teammates_in_view

BOUND_SLACK = 1e-9
"""Relative rounding allowed over k_v and k_ω π (a command computed as k_v·cos(0) is k_v exactly, but one
built from a product of bounds may round one ulp over)."""


class PluginCommandError(RuntimeError):
    """A controller's command that no robot may apply; the message names the controller, the robot and the step."""


def decide_with(
    controller: Controller,
    scenario: Scenario,
    step: int,
    coverage: np.ndarray,
    pose: tuple[float, float, float],
    objective: tuple[float, float],
    law: LawParameters,
    ground: Ground,
    positions: np.ndarray,
    me: int,
) -> tuple[float, float, float, int, int, np.ndarray]:
    """(v, ω, e_Ω, row0, col0, ticks) of robot ``me``: its wedge read as :func:`model.step.decide_and_sense`
    reads it, its command from ``controller``. Raises PluginCommandError when the command raises, is not two
    finite numbers or leaves eq. 15–16's bounds."""
    x, y, theta = pose
    teammates = teammates_in_view(ground, positions, me, x, y, law.sensing_range)
    e_omega, w_left, w_right, row0, col0, ticks = read_wedge(coverage, x, y, theta, law, ground, teammates)
    view = RobotView(
        me, step, x, y, theta, objective[0], objective[1], e_omega, w_left, w_right,
        _read_only(coverage), law.target_ticks, _read_only(positions), scenario,
    )  # fmt: skip
    v, omega = checked_command(controller, view)
    return v, omega, e_omega, row0, col0, ticks


def checked_command(controller: Controller, view: RobotView) -> tuple[float, float]:
    """``controller.command(view)`` as two floats within the bounds, or PluginCommandError naming it."""
    where = f"controller {view.scenario.controller!r}, robot {view.agent}, step {view.step}"
    try:
        command = controller.command(view)
    except Exception as error:  # whatever a plug-in raises, the team hears which one and where
        raise PluginCommandError(f"{where}: command() raised {type(error).__name__}: {error}") from error
    try:
        if isinstance(command, str | bytes):
            raise TypeError("a string is not a command")
        v, omega = (float(value) for value in command)
    except (TypeError, ValueError) as error:
        raise PluginCommandError(f"{where}: command() returned {command!r}, expected (v, omega)") from error
    v_max, omega_max = command_bounds(view.scenario)
    if not (math.isfinite(v) and math.isfinite(omega)):
        raise PluginCommandError(f"{where}: command() returned (v, omega) = ({v}, {omega}), expected finite numbers")
    if abs(v) > v_max * (1.0 + BOUND_SLACK) or abs(omega) > omega_max * (1.0 + BOUND_SLACK):
        raise PluginCommandError(
            f"{where}: command() returned (v, omega) = ({v}, {omega}), outside |v| <= k_v = {v_max}, "
            f"|omega| <= k_omega pi = {omega_max} (eq. 15-16)"
        )
    return v, omega


def _read_only(array: np.ndarray) -> np.ndarray:
    view = array.view()
    view.flags.writeable = False
    return view
