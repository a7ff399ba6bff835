"""The robot behind an agent: where it is and how it is commanded.

A real robot driver implements :class:`Robot` (read the localisation, send
(v, ω) to the base; :class:`agents.ros2.driver.Ros2Robot` for ROS 2 bases);
:class:`SimulatedUnicycle` integrates eq. 1 instead.
"""

from __future__ import annotations

from typing import Protocol

from model.step import LawParameters, move
from model.world.ground import Ground
from protocol.messages import Pose


class Robot(Protocol):
    def pose(self) -> Pose:
        """The latest (x, y, θ) in domain coordinates, fresh or not (hellos, held steps)."""
        ...

    def current_pose(self) -> Pose | None:
        """The pose this step acts on, read once; None when it is not known to be fresh (a real base's
        stale odometry): the agent then holds the robot still this step."""
        ...

    def command(self, v: float, omega: float) -> Pose:
        """Apply (v, ω) for one control period from the pose :meth:`current_pose` gave; return the pose
        at its end (a real base: the pose it reaches if it follows the command)."""
        ...

    def stop(self) -> None:
        """Zero velocity now (the end of the run, a signal, an error)."""
        ...

    @property
    def last_command(self) -> tuple[float, float]:
        """The (v, ω) the last :meth:`command` applied: a real base's limits may have clamped it."""
        ...


class SimulatedUnicycle:
    """A unicycle moved by eq. 1, exactly as the in-process engine moves it."""

    def __init__(self, initial: Pose, law: LawParameters, ground: Ground) -> None:
        self._pose = (float(initial[0]), float(initial[1]), float(initial[2]))
        self._law = law
        self._ground = ground  # walls stop it as they stop the engine's robots
        self.last_command = (0.0, 0.0)

    def pose(self) -> Pose:
        return self._pose

    def current_pose(self) -> Pose:
        return self._pose

    def command(self, v: float, omega: float) -> Pose:
        self.last_command = (v, omega)
        self._pose = move(*self._pose, v, omega, self._law, self._ground)
        return self._pose

    def stop(self) -> None:
        self.last_command = (0.0, 0.0)
