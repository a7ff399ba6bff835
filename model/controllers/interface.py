"""What a controller is: the one interface the engine, the agent process and the coordinator call.

A controller has two halves, as the paper's has (Section IV):

- **the team's plan** (:meth:`Controller.planner`): what the planner gives each robot every
  :meth:`Controller.plan_steps` steps, from the map's lack of coverage Υ and the robots' positions: an
  objective (Algorithms 1–2), a carrot along a route, a station's bearing. The engine and the coordinator
  both run it; its answer travels in the paper's ``Objectives`` message.
- **one robot's step** (:meth:`Controller.command`): the (v, ω) one robot applies, from what it knows (its
  pose, its replica of the map, what its camera reads this step, its objective), within eq. 15–16's bounds
  |v| ≤ k_v, |ω| ≤ k_ω π. The engine and the agent both call it, so a team over Zenoh in lockstep equals the
  engine byte for byte.

The built-in controllers implement the step as a compiled law (:meth:`Controller.law`: the parameters of
the numba kernel :func:`model.step.decide_and_sense`), which is what makes 3,000-run sweeps fast; a
controller written in Python overrides :meth:`Controller.command` instead and runs through
:func:`model.controllers.plugin_step.decide_with`, which checks every command it returns.

:class:`Supports` says what a controller can work with (walls, robot bodies, local planning, a team of
processes); the scenario check asks it instead of keeping lists of names (:mod:`model.controllers.registry`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, Protocol

import numpy as np

from model.controllers.algorithms import Planner
from model.planning import TeamPlanner
from model.step import LawParameters

if TYPE_CHECKING:
    from model.scenario import Scenario


@dataclass(frozen=True)
class Supports:
    """What a controller can work with; a scenario that needs more is refused, naming the controller."""

    terrain: bool = True  # a map, obstacles or robots with a body (robot_radius > 0)
    local_planning: bool = True  # planning = "local": every robot runs the planner on its own replica
    team: bool = True  # a team of processes over the bus (agents decide step by step); False: the engine only


class Pilot(Protocol):
    """One robot's path planned once for the team (:meth:`Controller.pilots`)."""

    @property
    def finished(self) -> bool: ...

    def velocities(self, x: float, y: float, theta: float) -> tuple[float, float]: ...


@dataclass(frozen=True)
class RobotView:
    """What one robot knows at step k, as :meth:`Controller.command` reads it (arrays are read-only).

    The coverage Λ of cell (row, col) is ``coverage[row, col] / target_ticks`` of Λ* (cell centres at
    ((col + ½)·cell, (row + ½)·cell), row 0 at the bottom); Υ = max(0, 1 − Λ/Λ*) (eq. 4)."""

    agent: int
    step: int
    x: float
    y: float
    theta: float
    objective_x: float  # what the planner gave this robot at its last plan (every step has one)
    objective_y: float
    e_omega: float  # eq. 6: the mean lack of coverage over the wedge this step
    w_left: float  # eq. 9 split by side: the uncovered weight left and right of the heading
    w_right: float
    coverage: np.ndarray  # int64 ticks (rows, cols): this robot's replica, before this step's deltas
    target_ticks: int  # Λ* in ticks
    positions: np.ndarray  # (N, 2): every robot's last known position (this one's at row ``agent``)
    scenario: Scenario

    @property
    def lack(self) -> np.ndarray:
        """Υ per cell, eq. 4 (cells nobody can cover are at Λ* already: Υ = 0)."""
        return np.clip(1.0 - self.coverage / self.target_ticks, 0.0, 1.0)


class Controller:
    """A controller (see the module's docstring). Subclass it, give it a ``name``, and override
    :meth:`command` (a controller written in Python) or :meth:`law` (a compiled one), and :meth:`planner`
    to plan for the team otherwise than Algorithms 1–2 do (:class:`model.controllers.algorithms.Planner`)."""

    name: ClassVar[str] = ""
    supports: ClassVar[Supports] = Supports(terrain=False, local_planning=False)

    def planner(self, scenario: Scenario) -> TeamPlanner:
        """A fresh planner for one run (it may keep state between plans)."""
        return Planner(scenario)

    def refuses(self, scenario: Scenario) -> str | None:
        """Why this controller cannot run a scenario its :attr:`supports` admit (naming the key and what it
        expects), or None (the default)."""
        return None

    def plan_steps(self, scenario: Scenario) -> int:
        """Steps between two plans (default: ``replan_period``'s)."""
        return scenario.replan_steps

    def law(self, scenario: Scenario, target_ticks: int) -> LawParameters:
        """The sensor's parameters, and for a compiled controller its law's (the paper's readings by
        default: :func:`paper_law`)."""
        return paper_law(scenario, target_ticks)

    def pilots(self, scenario: Scenario, poses: np.ndarray) -> list[Pilot] | None:
        """For a controller whose robots fly paths planned once for the team (the zig-zags): one pilot per
        robot, and the engine runs them to their end; None (the default): plan and step as above."""
        return None

    @property
    def flies_pilots(self) -> bool:
        """Whether its robots fly paths planned once (:meth:`pilots`): the engine runs them, a team cannot."""
        return type(self).pilots is not Controller.pilots

    @property
    def compiled(self) -> bool:
        """Whether the step is the compiled kernel's (:meth:`law`) rather than :meth:`command`."""
        return type(self).command is Controller.command

    def command(self, view: RobotView) -> tuple[float, float]:
        """(v, ω) for one robot this step, |v| ≤ k_v and |ω| ≤ k_ω π (eq. 15–16's bounds)."""
        raise NotImplementedError(f"controller {self.name!r} defines neither command() nor a compiled law")


def paper_law(
    scenario: Scenario, target_ticks: int, literal_heading: bool = False, literal_omega: bool = False
) -> LawParameters:
    """The paper's law and sensor with the scenario's parameters (eq. 2–16); the flags select the
    printed readings of eq. 11 and eq. 16 (docs/paper-notes.md, readings 4 and 6)."""
    return LawParameters(
        sensing_range=scenario.range,
        half_angle=scenario.half_angle,
        alpha_max=scenario.alpha_max,
        beta=scenario.beta,
        k_v=scenario.k_v,
        k_omega=scenario.k_omega,
        dt=scenario.dt,
        cell=scenario.cell,
        target_ticks=target_ticks,
        literal_heading=literal_heading,
        literal_omega=literal_omega,
    )


def command_bounds(scenario: Scenario) -> tuple[float, float]:
    """(k_v, k_ω π): the bounds every command keeps (eq. 15–16)."""
    return scenario.k_v, math.pi * scenario.k_omega
