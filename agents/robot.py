"""The robot behind an agent: where it is and how it is commanded.

A real robot driver implements :class:`Robot` (read the localisation, send
(v, ω) to the base); :class:`SimulatedUnicycle` integrates eq. 1 instead.
"""

from __future__ import annotations

from typing import Protocol

from model.ground import Ground
from model.step import LawParameters, move
from protocol.messages import Pose


class Robot(Protocol):
    def pose(self) -> Pose:
        """Current (x, y, θ) in domain coordinates."""
        ...

    def command(self, v: float, omega: float) -> Pose:
        """Apply (v, ω) for one control period; return the pose at its end."""
        ...


class SimulatedUnicycle:
    """A unicycle moved by eq. 1, exactly as the in-process engine moves it."""

    def __init__(self, initial: Pose, law: LawParameters, ground: Ground) -> None:
        self._pose = (float(initial[0]), float(initial[1]), float(initial[2]))
        self._law = law
        self._ground = ground  # walls stop it as they stop the engine's robots

    def pose(self) -> Pose:
        return self._pose

    def command(self, v: float, omega: float) -> Pose:
        self._pose = move(*self._pose, v, omega, self._law, self._ground)
        return self._pose
