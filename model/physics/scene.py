"""The physics world as MuJoCo's MJCF: a floor, the walls as static boxes, and one wheeled body per robot.

A robot (:class:`model.physics.base.Base`, every length in the scenario's units): a free body whose origin is
the midpoint of its wheels' axle at axle height, so that its (x, y, yaw) is the unicycle's pose (eq. 1); a
cylinder of radius r as its chassis, its bottom half a wheel radius off the floor; two wheels on hinges at
±b/2 (spheres of the wheel's radius: one contact point each; a cylinder's several across its width scrub
when the base turns, and it turned 11 % short of the commanded ω), each driven by a velocity servo whose torque is bounded by :attr:`Base.wheel_torque`; and two casters,
spheres front and back. The casters take part in contacts with ``priority`` over the floor and one
contact dimension, so they roll without friction: without it they take the floor's friction and the base
turns like a sledge.

The walls are the squares of the world's ``wall_grid`` (what the filter and the camera meet), merged into
as few boxes as runs of rows allow; a bounded map's edges are walls too.
"""

from __future__ import annotations

import math

import numpy as np

from model.physics.base import Base
from model.world.ground import Ground

PHYSICS_SUBSTEPS = 50
"""Physics steps per control period: 0.002 s at dt = 0.1 s, where the Burger-sized servo is stable."""
SERVO_STEPS = 4.0
"""A wheel servo's time constant, in physics steps: stiff enough to track, loose enough to stay stable."""
CONTACT_STEPS = 2.0
"""Contacts' time constant, in physics steps (MuJoCo's stiffest stable): at its default, 0.02 s, a wheel sank
so far into the floor that it rolled 4 % short of its radius."""
WHEEL_BIT = 2
"""The wheels' contact bit: they touch the floor only. A sphere wheel at ±b/2 reaches b/2 + r_w (1.07 r with the
defaults) from the axis, past the body the filter keeps apart; robots and walls meet at the chassis."""
GRAVITY = 9.81
"""In length units per time unit squared: metres and seconds on the real maps."""
WALL_HEIGHT = 3.0
"""Wall height over the body's radius: taller than any body."""


def wall_boxes(wall_grid: np.ndarray, grain: float) -> list[tuple[float, float, float, float]]:
    """The occupied squares of ``wall_grid`` (row = y, column = x, sides of ``grain``) as boxes (x0, y0, x1, y1):
    runs along each row, stacked while the next row has the same run."""
    boxes: list[tuple[float, float, float, float]] = []
    open_runs: dict[tuple[int, int], int] = {}  # (first column, last column + 1) -> first row
    for row in range(wall_grid.shape[0] + 1):
        runs = set(_runs(wall_grid[row])) if row < wall_grid.shape[0] else set()
        for run in [run for run in open_runs if run not in runs]:
            first = open_runs.pop(run)
            boxes.append((run[0] * grain, first * grain, run[1] * grain, row * grain))
        for run in runs:
            open_runs.setdefault(run, row)
    return sorted(boxes)


def _runs(line: np.ndarray) -> list[tuple[int, int]]:
    """(start, end) of every run of True in a row."""
    padded = np.concatenate([[False], line.astype(bool), [False]])
    edges = np.flatnonzero(padded[1:] != padded[:-1])
    return [(int(start), int(end)) for start, end in zip(edges[::2], edges[1::2], strict=True)]


def scene_xml(domain: tuple[float, float], ground: Ground, base: Base, poses: np.ndarray, dt: float) -> str:
    """The MJCF of the world: robots at ``poses`` (N, 3), stepped ``PHYSICS_SUBSTEPS`` times a period ``dt``."""
    width, height = domain
    wall_top = WALL_HEIGHT * base.radius
    walls = wall_boxes(ground.wall_grid, ground.grain) if ground.walls else []
    if ground.bounded:
        thick = max(ground.grain, base.radius)
        walls += [
            (-thick, -thick, width + thick, 0.0),
            (-thick, height, width + thick, height + thick),
            (-thick, 0.0, 0.0, height),
            (width, 0.0, width + thick, height),
        ]
    geoms = "\n".join(
        f'    <geom name="wall{k}" type="box" pos="{(x0 + x1) / 2} {(y0 + y1) / 2} {wall_top / 2}" '
        f'size="{(x1 - x0) / 2} {(y1 - y0) / 2} {wall_top / 2}" rgba="0.5 0.5 0.5 1"/>'
        for k, (x0, y0, x1, y1) in enumerate(walls)
    )
    robots = "\n".join(_robot_xml(i, pose, base) for i, pose in enumerate(poses))
    actuators = "\n".join(_servo_xml(i, base, dt) for i in range(len(poses)))
    floor = max(width, height)
    return f"""<mujoco model="anicov">
  <option timestep="{dt / PHYSICS_SUBSTEPS}" gravity="0 0 {-GRAVITY}" integrator="implicitfast"/>
  <default>
    <geom solref="{CONTACT_STEPS * dt / PHYSICS_SUBSTEPS} 1"/>
  </default>
  <worldbody>
    <geom name="floor" type="plane" pos="{width / 2} {height / 2} 0" size="{floor} {floor} 0.1"
          friction="{base.friction} 0.005 0.0001" conaffinity="{1 | WHEEL_BIT}"/>
{geoms}
{robots}
  </worldbody>
  <actuator>
{actuators}
  </actuator>
</mujoco>
"""


def _robot_xml(i: int, pose: np.ndarray, base: Base) -> str:
    r, wheel = base.radius, base.wheel_radius
    half_height = 0.5 * r
    chassis_z = 0.5 * wheel + half_height - wheel  # its bottom half a wheel radius off the floor
    caster = 0.5 * wheel
    yaw = math.degrees(float(pose[2]))
    wheels = "\n".join(
        f'      <body name="{side}{i}" pos="0 {sign * base.wheel_separation / 2} 0">\n'
        f'        <joint name="{side}{i}" type="hinge" axis="0 1 0"/>\n'
        f'        <geom name="{side}wheel{i}" type="sphere" size="{wheel}" '
        f'mass="{0.1 * base.mass}" friction="{base.friction} 0.005 0.0001" contype="{WHEEL_BIT}" conaffinity="0"/>\n'
        "      </body>"
        for side, sign in (("left", 1.0), ("right", -1.0))
    )
    casters = "\n".join(
        f'      <geom name="caster{end}{i}" type="sphere" size="{caster}" pos="{sign * 0.7 * r} 0 {caster - wheel}" '
        f'mass="{0.01 * base.mass}" condim="1" priority="1"/>'
        for end, sign in (("front", 1.0), ("back", -1.0))
    )
    return (
        f'    <body name="robot{i}" pos="{pose[0]} {pose[1]} {wheel}" euler="0 0 {yaw}">\n'
        f'      <freejoint name="robot{i}"/>\n'
        f'      <geom name="chassis{i}" type="cylinder" size="{r} {half_height}" pos="0 0 {chassis_z}" '
        f'mass="{0.78 * base.mass}"/>\n'
        f"{wheels}\n{casters}\n"
        "    </body>"
    )


def _servo_xml(i: int, base: Base, dt: float) -> str:
    """Each wheel's velocity servo: torque kv (target − speed), bounded by the base's wheel torque."""
    inertia = 0.5 * base.mass * base.wheel_radius**2  # half the base's mass, seen through one wheel
    gain = inertia / (SERVO_STEPS * dt / PHYSICS_SUBSTEPS)
    torque = base.wheel_torque
    return "\n".join(
        f'    <velocity name="{side}{i}" joint="{side}{i}" kv="{gain}" forcelimited="true" '
        f'forcerange="{-torque} {torque}"/>'
        for side in ("left", "right")
    )
