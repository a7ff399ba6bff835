"""The terrain keys of a scenario (issue 11): a map, polygons, the robot's body, occlusion, priorities.

Checked here, before any process starts; every problem raises :class:`model.scenario.terrain.TerrainError`
naming the key or the file (the scenario loader reports it as a scenario error).

- ``map = "office.yaml"``: a ROS map (or an MRPT ``.gridmap[.gz]``, :mod:`model.scenario.map_file`), relative to the scenario file. The domain is the map's known extent
  (:mod:`model.scenario.map_fit`: the unknown border cropped, padded to whole cells; ``domain``, if given,
  must agree), and the coverage cell is the map's resolution unless ``cell`` says otherwise (a whole number
  of pixels). The model's domain starts at (0, 0) at the fitted map's lower-left corner; what a user reads
  (trajectory.csv, a ROS 2 base's frames) is in the map's own frame.
- ``obstacles = [[[x, y], ...], ...]``: polygons, with or without a map; with one, in the map's frame (as
  ``initial_poses`` are).
- ``wall_detail = "map"`` (the default) or ``"cell"``: how finely bodies and cameras meet the walls
  (:func:`model.world.world.grain_split_of`): to the map's pixel, up to 5 squares a cell side, or to whole
  cells (a cell with any wall pixel is a wall: the fit before issue 34, kept by the drawn maps' studies).
- ``robot_radius`` (≥ 0) and ``occlusion`` (true or false).
- ``lambda_star = "priority.png"`` with ``lambda_star_min`` and ``lambda_star_max``: a priority map,
  grey level 0 → the minimum, 255 → the maximum.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from model.scenario.map_file import load_map
from model.scenario.map_fit import fit_to_cells
from model.scenario.terrain import TerrainError, check_polygon


def _finite(key: str, value: Any, low: float) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or value < low:
        raise TerrainError(f"scenario key '{key}': expected a finite number of at least {low}, got {value!r}")
    return float(value)


def _resolve_map(values: dict[str, Any], base: Path) -> None:
    name = values["map"]
    if not isinstance(name, str) or not name:
        raise TerrainError(f"scenario key 'map': expected the path of a ROS map YAML file, got {name!r}")
    path = (base / name).resolve()
    if not path.is_file():
        raise TerrainError(f"scenario key 'map': the map file {path} does not exist")
    occupancy_map = load_map(path)
    values.setdefault("cell", occupancy_map.resolution)
    cell = values["cell"]
    if isinstance(cell, bool) or not isinstance(cell, int | float) or not math.isfinite(cell) or cell <= 0:
        raise TerrainError(
            f"scenario key 'cell': expected a whole multiple of the map's resolution {occupancy_map.resolution}, "
            f"got {cell!r}"
        )
    extent = fit_to_cells(occupancy_map, float(cell)).extent  # the unknown border cropped, whole cells
    if "domain" in values:
        given = values["domain"]
        if (
            not isinstance(given, list | tuple)
            or len(given) != 2
            or any(abs(float(a) - b) > 1e-9 * b for a, b in zip(given, extent, strict=True))
        ):
            raise TerrainError(
                f"scenario key 'domain': the map {path} spans {list(extent)}; leave 'domain' out or give that, "
                f"got {given!r}"
            )
    values["domain"] = list(extent)
    values["map"] = str(path)


def _resolve_priority(values: dict[str, Any], base: Path) -> None:
    name = values["lambda_star"]
    if not name:
        raise TerrainError("scenario key 'lambda_star': expected a number or the path of a priority image")
    path = (base / name).resolve()
    if not path.is_file():
        raise TerrainError(f"scenario key 'lambda_star': the priority image {path} does not exist")
    for key in ("lambda_star_min", "lambda_star_max"):
        if key not in values:
            raise TerrainError(f"scenario key '{key}': a priority map needs lambda_star_min and lambda_star_max")
    low = _finite("lambda_star_min", values["lambda_star_min"], 0.0)
    high = _finite("lambda_star_max", values.pop("lambda_star_max"), 0.0)
    if not 0.0 < low <= high:
        raise TerrainError(f"scenario key 'lambda_star_min': expected 0 < min <= max ({high}), got {low!r}")
    values["priority_map"] = str(path)
    values["lambda_star"] = high
    values["lambda_star_min"] = low


def resolve_terrain_keys(values: dict[str, Any], base: Path) -> dict[str, Any]:
    """The scenario's values with the terrain keys checked and resolved (see the module's docstring)."""
    if values.get("map"):
        _resolve_map(values, base)
    elif "map" in values and values["map"] != "":
        raise TerrainError(f"scenario key 'map': expected the path of a ROS map YAML file, got {values['map']!r}")
    if "obstacles" in values:
        polygons = values["obstacles"]
        if not isinstance(polygons, list | tuple):
            raise TerrainError(f"scenario key 'obstacles': expected a list of polygons [[x, y], ...], got {polygons!r}")
        values["obstacles"] = tuple(
            tuple((float(x), float(y)) for x, y in check_polygon(index, polygon))
            for index, polygon in enumerate(polygons)
        )
    if "wall_detail" in values and values["wall_detail"] not in ("map", "cell"):
        raise TerrainError(f'scenario key \'wall_detail\': expected "map" or "cell", got {values["wall_detail"]!r}')
    if "robot_radius" in values:
        values["robot_radius"] = _finite("robot_radius", values["robot_radius"], 0.0)
    if "occlusion" in values and not isinstance(values["occlusion"], bool):
        raise TerrainError(f"scenario key 'occlusion': expected true or false, got {values['occlusion']!r}")
    if isinstance(values.get("lambda_star"), str):
        _resolve_priority(values, base)
    elif "lambda_star_max" in values or "lambda_star_min" in values:
        raise TerrainError("scenario key 'lambda_star_min': only with lambda_star naming a priority image")
    return values
