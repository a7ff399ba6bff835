"""A map file of any format the scenario's ``map`` key takes: a ROS map (YAML and image,
:func:`model.scenario.terrain.load_occupancy_map`) or an MRPT grid map (:mod:`model.scenario.mrpt_gridmap`)."""

from __future__ import annotations

from pathlib import Path

from model.scenario.mrpt_gridmap import is_mrpt_gridmap, load_mrpt_gridmap
from model.scenario.terrain import OccupancyMap, load_occupancy_map


def load_map(path: str | Path) -> OccupancyMap:
    """The map at ``path``, read by its format (the file's name says which); TerrainError naming the file."""
    path = Path(path)
    return load_mrpt_gridmap(path) if is_mrpt_gridmap(path) else load_occupancy_map(path)
