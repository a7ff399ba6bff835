"""The bases ``anicov sim`` plays: every robot of the scenario in one physics world, and what their sensors say.

:class:`SimulatedBases` holds :class:`model.physics.team.PhysicalTeam` (the MuJoCo world, the commands in flight
to the wheels, the truth's own map) and :class:`model.physics.noise.Sensors`. It takes each base's latest
command in ROS units, steps the world one control period, and says what each base publishes in the ROS
``map`` frame (:func:`protocol.ros2.frames.frame_of`, the same frame the agents' driver reads):

- **odometry**: the odom frame is the map frame at the start (as a base whose odometry is given the start pose),
  so without noise it is the true pose; with ``[noise]`` it drifts as wheel odometry does;
- **localiser fixes** (``[noise]`` with a ``localiser_rate``): the true pose with the localiser's σ, stamped at
  the instant it measured and handed out ``localiser_latency`` later, as AMCL publishes ``amcl_pose``. The
  driver turns them into the map ← odom correction, pairing each with the odometry of its stamp.

Stamps are simulated time (ROS's ``use_sim_time``): step k is ``k dt seconds_per_unit`` seconds. Nothing here
touches the bus (simulator/process.py does), so a test can step it alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.controllers import law_parameters
from model.parameters import starting_poses
from model.physics.noise import Sensors, moved_by, noise_of
from model.physics.team import PhysicalTeam
from model.scenario import Scenario
from model.world.world import world_of
from protocol.ros2.frames import Pose, frame_of

NANOSECONDS = 1_000_000_000


@dataclass(frozen=True)
class Reading:
    """What one base publishes after a step: its odometry and the localiser's fixes that arrive now (map frame,
    metres, radians; stamps in nanoseconds of simulated time)."""

    agent: int
    stamp_ns: int
    odometry: Pose
    velocity: tuple[float, float]  # m/s, rad/s: the command the wheels took
    fixes: tuple[tuple[int, Pose], ...] = ()
    start: bool = False  # the fix is the start pose, exact (as an operator gives AMCL its initial pose)


class SimulatedBases:
    """Every robot's base (see the module); poses in scenario units inside, map-frame metres out."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.frame = frame_of(scenario)
        self.ground = world_of(scenario).ground
        self.team = PhysicalTeam(scenario, starting_poses(scenario), self.ground)
        self.noise = noise_of(scenario)
        self.sensors = Sensors(self.noise, self.team.truth, scenario.seed)
        self.law = law_parameters(scenario, self.team.true_map)
        self.odometry = self.team.truth.copy()  # scenario units; the odom frame is the map frame at the start
        self.commands = np.zeros((scenario.agents, 2))  # scenario units, what each base was last told
        self.step = 0
        self.sensing = True  # the truth's map takes what the cameras see until the run is declared over

    @property
    def agents(self) -> int:
        return self.scenario.agents

    @property
    def localiser(self) -> bool:
        """Whether the bases publish a localiser's fixes (a ``[noise]`` table with a ``localiser_rate``)."""
        return self.noise.localiser_period > 0

    def command(self, agent: int, linear: float, angular: float) -> None:
        """Base ``agent``'s latest command (m/s, rad/s), for the next step."""
        self.commands[agent] = self.frame.to_scenario_velocity(linear, angular)

    def stamp_ns(self, step: int) -> int:
        return round(step * self.scenario.dt * self.scenario.seconds_per_unit * NANOSECONDS)

    def advance(self) -> list[Reading]:
        """One control period: the cameras' truth sensed at t_k, the wheels driven, the world stepped; what each
        base publishes at t_{k+1}."""
        commands = self.commands.copy()
        truth = self.team.move(commands, self.law, self.ground, sense=self.sensing)
        self.step += 1
        if self.noise.none:
            self.odometry = truth.copy()
            return self.readings(commands)
        motion, arrived = self.sensors.update(truth)
        self.odometry = moved_by(self.odometry, motion)
        return self.readings(commands, arrived)

    def readings(
        self, commands: np.ndarray | None = None, arrived: list[tuple[int, np.ndarray]] | tuple = ()
    ) -> list[Reading]:
        """What every base publishes now (at the start: its odometry and, with a localiser, its known start
        pose as the first fix, as an operator gives AMCL its initial pose)."""
        start = not arrived and self.step == 0 and self.localiser
        if start:
            arrived = [(0, self.team.truth)]
        commands = self.commands if commands is None else commands
        readings = []
        for agent in range(self.agents):
            fixes = tuple(
                (self.stamp_ns(measured_at), self.frame.pose_to_map(tuple(fix[agent]))) for measured_at, fix in arrived
            )
            readings.append(
                Reading(
                    agent,
                    self.stamp_ns(self.step),
                    self.frame.pose_to_map(tuple(self.odometry[agent])),
                    self.frame.to_ros_velocity(float(commands[agent, 0]), float(commands[agent, 1])),
                    fixes,
                    start,
                )
            )
        return readings

    def figures(self) -> dict[str, float | int]:
        """summary.json's physics and truth figures (:meth:`model.physics.team.PhysicalTeam.figures`), and the
        steps simulated."""
        return self.team.figures() | {"simulated_steps": self.step}
