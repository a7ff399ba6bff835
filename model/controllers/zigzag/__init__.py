"""The zig-zag baselines: Fig. 8's lanes in contiguous blocks, and the boustrophedon (the same path cut in N
pieces of equal length). Each robot flies a path planned once for the team; the engine runs them
(:meth:`model.controllers.interface.Controller.pilots`), in the paper's open domain only."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from model.controllers.interface import Controller, Supports
from model.controllers.zigzag.zigzag import WaypointPilot, boustrophedon_pilots, zigzag_pilots, zigzag_start_poses
from model.scenario import Scenario

OPEN_DOMAIN_ONLY = Supports(terrain=False, local_planning=False, team=False)


class ZigzagController(Controller):
    """Fig. 8 (docs/paper-notes.md, reading 3): the lanes split in contiguous blocks, one per robot."""

    name: ClassVar[str] = "zigzag"
    supports: ClassVar[Supports] = OPEN_DOMAIN_ONLY

    def pilots(self, scenario: Scenario, poses: np.ndarray) -> list[WaypointPilot] | None:
        return zigzag_pilots(scenario)

    @staticmethod
    def start_poses(scenario: Scenario) -> np.ndarray:
        """Each robot at the start of its first lane, facing along it (Fig. 8 as the paper flies it)."""
        return zigzag_start_poses(scenario)


class BoustrophedonController(Controller):
    """The zig-zag's path cut into N pieces of equal length, each flown by the robot whose start is nearest
    in the team's least total transit (:func:`model.controllers.zigzag.zigzag.boustrophedon_pilots`)."""

    name: ClassVar[str] = "boustrophedon"
    supports: ClassVar[Supports] = OPEN_DOMAIN_ONLY

    def pilots(self, scenario: Scenario, poses: np.ndarray) -> list[WaypointPilot] | None:
        return boustrophedon_pilots(scenario, poses)
