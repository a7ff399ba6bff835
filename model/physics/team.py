"""The robots' bodies and the truth, for whatever moves them by physics: the in-process engine
(anicov/physics_engine.py) and the simulator process (simulator/).

:class:`PhysicalTeam` holds the MuJoCo world (:class:`model.physics.world.PhysicsWorld`), the commands in
flight to the wheels (``command_latency``, :class:`model.physics.noise.CommandDelay`), and the coverage the
cameras really gave: by eq. 2 from the true poses, on a map of its own at Λ* of every coverable cell (the team's
own map may ask more, ``cover_margin``, take less, ``sure_sigmas``, and not ask the cells it cannot surely see,
``unsure_sigmas``). What a robot believes of its pose is not here: the
engine keeps :class:`model.physics.noise.Belief`, the simulator publishes odometry and fixes.
"""

from __future__ import annotations

import numpy as np

from model.parameters import coverage_map_of
from model.physics.base import base_of
from model.physics.noise import CommandDelay, noise_of
from model.physics.world import PhysicsWorld
from model.scenario import Scenario
from model.step import LawParameters, sense_only
from model.world.ground import Ground


class PhysicalTeam:
    """The world, the robots' late commands, and the truth's own map."""

    def __init__(self, scenario: Scenario, poses: np.ndarray, ground: Ground) -> None:
        noise = noise_of(scenario)
        self.world = PhysicsWorld(scenario.domain, ground, base_of(scenario), poses, scenario.dt)
        self.truth = self.world.poses()
        self.delay = CommandDelay(noise.command_delay, scenario.agents)
        self.true_map = coverage_map_of(scenario, with_margin=False)
        self.true_poses = [self.truth.copy()]

    def move(self, commands: np.ndarray, law: LawParameters, ground: Ground, sense: bool = True) -> np.ndarray:
        """The cameras sense from the true poses of t_k (unless ``sense`` is False: the run is over), the wheels
        take the commands due, the world steps; the true poses (N, 3) of t_{k+1}."""
        positions = self.truth[:, :2].copy()
        exact = law._replace(position_doubt=0.0, heading_doubt=0.0)  # the truth's camera is where it is
        for i, (x, y, theta) in enumerate(self.truth if sense else ()):
            self.true_map.add(*sense_only(self.true_map.coverage, x, y, theta, exact, ground, positions, i))
        self.truth = self.world.step(self.delay(commands))
        self.true_poses.append(self.truth.copy())
        return self.truth

    def figures(self) -> dict[str, float | int]:
        """What summary.json reports of the physics and the truth."""
        contacts, true_map = self.world.contacts, self.true_map
        return {
            "physical_contacts": contacts.total,
            "robot_contacts": contacts.robots,
            "wall_contacts": contacts.walls,
            "true_coverage": 1.0 - true_map.uncovered_cells / true_map.counted_cells,
            "true_cells_short": int(true_map.uncovered_cells),
        }
