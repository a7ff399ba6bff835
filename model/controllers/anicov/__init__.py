"""anicov's own controller (docs/controller.md): robots stand at stations and turn their camera through
bearings chosen by a linear programme, hopping between them (``stations = false``: a weaving spiral then
passes over what is left), steered by a carrot every :data:`route.CARROT_PERIOD`. Among walls and with robot
bodies it flies stations only (:mod:`model.controllers.anicov.terrain_plan` and what follows it). With
``planning = "local"`` each robot runs this planner on its own replica: every one cuts the same routes for
the whole team from the start poses (a teammate out of radio contact at its seeded one), and later plans
advance, patch and clean up for the teammates it hears; each robot follows only its own carrot."""

from __future__ import annotations

from typing import ClassVar

from model.controllers.anicov.lane_planner import LanePlanner
from model.controllers.anicov.law import anicov_law
from model.controllers.anicov.route import CARROT_PERIOD
from model.controllers.interface import Controller, Supports
from model.planning import TeamPlanner
from model.scenario import Scenario
from model.step import LawParameters


class AnicovController(Controller):
    """Stations (or the weaving spiral) planned by :class:`LanePlanner`, flown by pure pursuit."""

    name: ClassVar[str] = "anicov"
    supports: ClassVar[Supports] = Supports(terrain=True, local_planning=True, team=True)

    def refuses(self, scenario: Scenario) -> str | None:
        if scenario.has_terrain and not scenario.stations:
            return (
                "scenario key 'stations': false flies anicov's weaving spiral, which knows no walls or robot "
                "bodies; with map, obstacles or robot_radius use stations = true (the default)"
            )
        return None

    def planner(self, scenario: Scenario) -> TeamPlanner:
        return LanePlanner(scenario)

    def plan_steps(self, scenario: Scenario) -> int:
        return max(1, round(CARROT_PERIOD / scenario.dt))

    def law(self, scenario: Scenario, target_ticks: int) -> LawParameters:
        return anicov_law(scenario, target_ticks)
