"""The terrain as the step kernels read it: one tuple of arrays and scalars that numba takes as is.

:func:`model.world.world.World.ground` builds it from a scenario; :func:`open_ground` is the paper's open
world, in which every test it drives is skipped and a step is exactly the paper's.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

PLANNING_MARGIN = 0.05
"""Clearance, in cells, that paths and straight drives keep beyond the robot's radius. Motion itself
tests the exact disk; without the margin a planned drive that only touches a wall would be refused
by a step one rounding error off it, or by the arc of a unicycle that is not yet aligned."""


class Ground(NamedTuple):
    occupied: np.ndarray  # bool (rows, cols): coverage cells with a wall in them (nothing there to cover)
    passable: np.ndarray  # bool (rows, cols): centres that hold the robot's disk
    radius: float  # r
    plan_radius: float  # wall_clearance plus PLANNING_MARGIN (and world.FINE_WALL_MARGIN on fine walls): what paths and drives keep
    wall_clearance: float  # r, plus the safety margin s when the filter is on: what the law keeps off walls
    bounded: bool  # the map's edge is a wall
    walls: bool  # an occupied cell: the global law and the assignment go round them
    occlusion: bool  # lines of sight are tested (walls, or teammates' disks when r > 0)
    lookahead: int  # cells walked down a distance field for the global law's waypoint
    wall_grid: np.ndarray  # bool (rows·k, cols·k): the walls as bodies and cameras meet them, squares of ``grain``
    grain: float  # side of a wall_grid square: the cell, or a whole fraction of it (model.world.world.grain_split_of)


def open_ground() -> Ground:
    """No wall, no body, nothing hidden: the paper's world."""
    nothing = np.zeros((1, 1), dtype=np.bool_)
    return Ground(nothing, ~nothing, 0.0, 0.0, 0.0, False, False, False, 1, nothing, 1.0)


NO_FIELD = np.zeros((1, 1))
"""The distance field of an open world's objective: never read."""
NO_POSITIONS = np.zeros((0, 2))
"""Teammates' positions where nothing hides anything: never read."""
