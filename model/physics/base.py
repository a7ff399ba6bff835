"""A differential-drive base: its parameters in the scenario's units, and the wheel speeds of a command.

The defaults scale a TurtleBot3 Burger (body radius 0.105 m, wheels of 0.033 m radius 0.160 m apart, about
1 kg, 0.22 m/s, 2.5 m/s² of acceleration) to the scenario's ``robot_radius`` and ``k_v``
(:mod:`model.scenario.physics_keys`).
"""

from __future__ import annotations

from dataclasses import dataclass

from model.scenario import Scenario
from model.scenario.physics_keys import BURGER_ACCELERATION

BURGER_WHEEL_RADIUS = 0.31
"""Wheel radius over body radius: 0.033 / 0.105."""
BURGER_WHEEL_SEPARATION = 1.52
"""Wheel separation (centre to centre) over body radius: 0.160 / 0.105."""


@dataclass(frozen=True)
class Base:
    """One robot's base (every robot of a team has the same)."""

    radius: float  # the body's, r (robot_radius)
    mass: float
    wheel_radius: float
    wheel_separation: float
    acceleration: float  # the most the wheels' torque gives the base, at full grip
    friction: float  # the wheels' on the floor

    @property
    def wheel_torque(self) -> float:
        """The most torque one wheel gives: half of what accelerates the whole mass at ``acceleration``."""
        return 0.5 * self.mass * self.acceleration * self.wheel_radius


def base_of(scenario: Scenario) -> Base:
    """The scenario's ``[robot]`` table over the Burger's proportions."""
    given = dict(scenario.robot)
    radius = scenario.robot_radius
    return Base(
        radius=radius,
        mass=given.get("mass", 1.0),
        wheel_radius=given.get("wheel_radius", BURGER_WHEEL_RADIUS * radius),
        wheel_separation=given.get("wheel_separation", BURGER_WHEEL_SEPARATION * radius),
        acceleration=given.get("acceleration", BURGER_ACCELERATION * scenario.k_v),
        friction=given.get("friction", 1.0),
    )


def wheel_speeds(v: float, omega: float, base: Base) -> tuple[float, float]:
    """(left, right) wheel angular speeds that drive the unicycle's (v, ω) (eq. 1) when the wheels grip:
    a wheel's rim moves at v ∓ ω b/2, b the separation."""
    half = 0.5 * base.wheel_separation
    return (v - omega * half) / base.wheel_radius, (v + omega * half) / base.wheel_radius
