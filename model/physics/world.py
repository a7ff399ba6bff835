"""The physics world stepped once per control period, with every robot's command in (issue 37, item 1).

:meth:`PhysicsWorld.step` sets each robot's wheel servos to the speeds of its (v, ω)
(:func:`model.physics.base.wheel_speeds`), steps MuJoCo :data:`model.physics.scene.PHYSICS_SUBSTEPS` times
and reads back every robot's (x, y, yaw): the pose the next step starts from, in place of eq. 1's. One
world steps all robots at once, in robot order, so a run is the same every time (MuJoCo is deterministic
on one machine and build). At every physics step it also reads the contacts: a pair of robots, or a robot
and a wall, that touch in a period and did not in the period before is one new contact (:attr:`contacts`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from model.physics.base import Base, wheel_speeds
from model.physics.scene import PHYSICS_SUBSTEPS, scene_xml
from model.world.ground import Ground

WALL = -1
"""The owner of a wall's geom (a robot's geoms are owned by its index; the floor's by no one)."""


@dataclass
class Contacts:
    """New contact pairs so far, between two robots and between a robot and a wall."""

    robots: int = 0
    walls: int = 0
    touching: set[tuple[int, int]] = field(default_factory=set)  # the pairs that touched in the last period

    @property
    def total(self) -> int:
        return self.robots + self.walls


class PhysicsWorld:
    """Floor, walls and robots (see :mod:`model.physics.scene`); poses in and out are (N, 3) (x, y, θ)."""

    def __init__(self, domain: tuple[float, float], ground: Ground, base: Base, poses: np.ndarray, dt: float):
        self.base = base
        self.agents = len(poses)
        self.model = mujoco.MjModel.from_xml_string(scene_xml(domain, ground, base, np.asarray(poses), dt))
        self.data = mujoco.MjData(self.model)
        self.contacts = Contacts()
        self._owner_list = self._owners().tolist()
        self._qpos = [self.model.jnt_qposadr[self.model.joint(f"robot{i}").id] for i in range(self.agents)]
        self._servo = np.array(
            [[self.model.actuator(f"{side}{i}").id for side in ("left", "right")] for i in range(self.agents)]
        )
        mujoco.mj_forward(self.model, self.data)

    def _owners(self) -> np.ndarray:
        """For every geom: the robot it belongs to, WALL, or −2 (the floor)."""
        owner = np.full(self.model.ngeom, -2, dtype=np.int64)
        robots = {self.model.body(f"robot{i}").id: i for i in range(self.agents)}
        for geom in range(self.model.ngeom):
            body = int(self.model.geom_bodyid[geom])
            root = int(self.model.body_rootid[body])
            if root in robots:
                owner[geom] = robots[root]
            elif self.model.geom(geom).name.startswith("wall"):
                owner[geom] = WALL
        return owner

    def step(self, commands: np.ndarray) -> np.ndarray:
        """Drive every robot at its (v, ω) (``commands`` (N, 2)) for one control period; the poses (N, 3) after."""
        for i, (v, omega) in enumerate(commands):
            self.data.ctrl[self._servo[i]] = wheel_speeds(float(v), float(omega), self.base)
        touched: set[tuple[int, int]] = set()
        for _ in range(PHYSICS_SUBSTEPS):
            mujoco.mj_step(self.model, self.data)
            touched |= self._touching()
        self._count(touched)
        return self.poses()

    def poses(self) -> np.ndarray:
        """(N, 3): each robot's axle midpoint (x, y) and heading (its yaw, in (−π, π])."""
        out = np.empty((self.agents, 3))
        for i, address in enumerate(self._qpos):
            x, y, _, w, qx, qy, qz = self.data.qpos[address : address + 7]
            out[i] = x, y, math.atan2(2.0 * (w * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
        return out

    def _touching(self) -> set[tuple[int, int]]:
        """The pairs (robot, robot) and (WALL, robot) in contact at this physics step."""
        owner, touching = self._owner_list, set()
        for geom1, geom2 in self.data.contact.geom[: self.data.ncon].tolist():
            a, b = owner[geom1], owner[geom2]
            if a != b and a >= WALL and b >= WALL and a + b > 2 * WALL:  # not its own, the floor, wall on wall
                touching.add((a, b) if a < b else (b, a))
        return touching

    def _count(self, touched: set[tuple[int, int]]) -> None:
        """A pair that touched in this period and in no physics step of the one before is a new contact: two
        bodies pushed together bounce apart for a few milliseconds, which is one contact, not many."""
        for pair in touched - self.contacts.touching:
            if pair[0] == WALL:
                self.contacts.walls += 1
            else:
                self.contacts.robots += 1
        self.contacts.touching = touched
