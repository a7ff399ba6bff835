"""The paper's controller (eq. 6–16 with Algorithms 1–2), and its literal readings.

- ``paper``: the chosen readings of eq. 11 (toward the objective) and eq. 16 (docs/paper-notes.md);
- ``paper-literal``: both as printed;
- ``paper-eq16``: eq. 11 read toward the objective, eq. 16 as printed.

All three run among walls and with robot bodies (the global law follows the geodesic field,
:mod:`model.world.wall_law`), and with local planning.
"""

from __future__ import annotations

from typing import ClassVar

from model.controllers.interface import Controller, Supports, paper_law
from model.scenario import Scenario
from model.step import LawParameters

EVERYWHERE = Supports(terrain=True, local_planning=True, team=True)


class PaperController(Controller):
    """eq. 6–16 as read in docs/paper-notes.md, planned by Algorithms 1–2."""

    name: ClassVar[str] = "paper"
    supports: ClassVar[Supports] = EVERYWHERE


class PaperLiteralController(Controller):
    """eq. 11 and eq. 16 as printed (readings 4 and 6 of docs/paper-notes.md)."""

    name: ClassVar[str] = "paper-literal"
    supports: ClassVar[Supports] = EVERYWHERE

    def law(self, scenario: Scenario, target_ticks: int) -> LawParameters:
        return paper_law(scenario, target_ticks, literal_heading=True, literal_omega=True)


class PaperEq16Controller(Controller):
    """eq. 11 toward the objective, eq. 16 as printed (reading 6 of docs/paper-notes.md)."""

    name: ClassVar[str] = "paper-eq16"
    supports: ClassVar[Supports] = EVERYWHERE

    def law(self, scenario: Scenario, target_ticks: int) -> LawParameters:
        return paper_law(scenario, target_ticks, literal_omega=True)
