"""The world a team covers, built once per scenario: walls, where a robot can go, what it can see.

- ``wall_grid``: the walls as bodies and cameras meet them, on squares of ``grain`` (:func:`grain_split_of`: the cell,
  or a whole fraction of it where the map has walls finer than a cell; gaps filled by :func:`closed_gaps`): the map fitted to the coverage grid
  (:mod:`model.scenario.map_fit`: its unknown border cropped, padded to whole cells) or'd with the polygons
  (:func:`model.scenario.terrain.polygons_on_grid`). Every disk test (a robot's body, a straight drive, the
  safety filter's walls) and every line of sight reads it.
- ``occupied``: the coverage cells with a wall square in them: nothing there to cover.
- ``passable``: coverage-cell centres that hold the robot's disk with PLANNING_MARGIN to spare (and
  FINE_WALL_MARGIN where the wall squares are finer than the cell: :func:`plan_radius_of`), clear of the
  wall squares (:func:`model.world.geodesic.passable_cells`); two neighbours are joined when the disk drives
  straight from one centre to the other (:func:`model.world.geodesic.passage_graph`).
- ``graph``: that graph (CSR; None in the open world), for the distance fields.
- ``reachable``: the team's space, the largest 8-connected component of passable cells (lowest
  cell index on a tie). Every robot starts there (:func:`model.parameters.free_initial_poses`), so
  it is where any robot can go.
- ``coverable``: free cells some reachable pose can see (:mod:`model.world.reachability`), within
  :func:`viewing_range_of`. The others,
  occupied or not, start at Λ* in every replica (Υ = 0): Algorithm 1 never sees them, and e_D and
  completion count only coverable cells.
- ``targets``: Λ*(x) per cell in ticks, from the priority map when there is one.

In the paper's open world (no map, no polygon, point robots) every cell is passable, reachable and
coverable and nothing here changes a run.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from numba import njit
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from model.paper.fixed_point import COVERAGE_SCALE
from model.scenario import Scenario
from model.scenario.map_file import load_map
from model.scenario.map_fit import FittedMap, MapFrame, fit_to_cells
from model.scenario.physics_keys import safety_margin_of, unsure_spread_of
from model.scenario.terrain import (
    OccupancyMap,
    TerrainError,
    coarsen,
    file_sha256,
    polygons_on_grid,
)
from model.world.geodesic import distance_fields, grid_graph, passable_cells, passage_graph
from model.world.ground import PLANNING_MARGIN, Ground
from model.world.reachability import coverable_cells, seers, unsure_cells


@dataclass(frozen=True, eq=False)
class World:
    """See the module's docstring."""

    scenario: Scenario
    occupied: np.ndarray
    wall_grid: np.ndarray
    grain: float
    passable: np.ndarray
    graph: csr_matrix | None
    reachable: np.ndarray
    coverable: np.ndarray
    targets: np.ndarray  # int64 ticks: Λ*(x)
    map_sha256: str
    priority_sha256: str

    @property
    def open(self) -> bool:
        """The paper's world: nothing to test, every run exactly as before terrain existed."""
        return not self.scenario.has_terrain

    @functools.cached_property
    def ground(self) -> Ground:
        """Built once: the engine, the planner and the agent read it every step or plan."""
        scenario = self.scenario
        walls = bool(self.occupied.any())
        occlusion = scenario.occlusion and (bool(self.occupied.any()) or scenario.robot_radius > 0.0)
        lookahead = max(1, math.ceil(scenario.range / scenario.cell))
        return Ground(
            self.occupied,
            self.passable,
            scenario.robot_radius,
            plan_radius_of(scenario, self.grain < scenario.cell),
            wall_clearance_of(scenario),
            bool(scenario.map),
            walls,
            occlusion,
            lookahead,
            self.wall_grid,
            self.grain,
        )

    @property
    def unreachable_cells(self) -> int:
        """Free cells that no reachable pose can see: left out of e_D and of completion."""
        return int((~self.occupied & ~self.coverable).sum())

    @property
    def coverable_area(self) -> float:
        return float(self.coverable.sum()) * self.scenario.cell**2

    @functools.cached_property
    def unsure(self) -> np.ndarray:
        """Coverable cells a robot cannot be sure to see with a localiser's noise: no reachable cell sees them from its
        centre and from the eight points :func:`model.scenario.physics_keys.unsure_spread_of` off it
        (:func:`model.world.reachability.unsure_cells`). The team's map does not ask them
        (:func:`model.parameters.coverage_map_of`); the truth's still counts them."""
        scenario = self.scenario
        return unsure_cells(
            self.wall_grid, self.grain, self.reachable, self.coverable, viewing_range_of(scenario), scenario.cell,
            unsure_spread_of(scenario),
        )  # fmt: skip

    def head_start(self, target_ticks: int, scale: float = 1.0) -> np.ndarray:
        """Ticks every replica starts with: Λ* on cells nobody can cover, and Λ*_max − Λ*(x) on the
        rest (a priority map's lower targets as a head start on one common target). ``scale``: every Λ*(x)
        asked that many times over (a noisy team's cover margin, :func:`model.parameters.coverage_map_of`)."""
        targets = self.targets if scale == 1.0 else np.rint(self.targets * scale).astype(np.int64)
        return np.where(self.coverable, np.maximum(target_ticks - targets, 0), target_ticks).astype(np.int64)

    def field(self, x: float, y: float) -> np.ndarray:
        """Geodesic distance to the cell of (x, y) from every cell (:func:`model.world.geodesic.distance_fields`)."""
        rows, cols = self.occupied.shape
        cell = self.scenario.cell
        row, col = min(max(math.floor(y / cell), 0), rows - 1), min(max(math.floor(x / cell), 0), cols - 1)
        return self._field(row, col)

    def seers_of(self, x: float, y: float) -> np.ndarray:
        """The reachable cells that see the centre of the cell about (x, y) (:func:`model.world.reachability.seers`
        within :func:`viewing_range_of`: what coverable means), (M, 3) rows (gap, centre x, centre y), nearest
        first."""
        cell = self.scenario.cell
        centre_x, centre_y = (math.floor(x / cell) + 0.5) * cell, (math.floor(y / cell) + 0.5) * cell
        return seers(
            self.wall_grid, self.grain, self.reachable, centre_x, centre_y, viewing_range_of(self.scenario), cell
        )

    @functools.lru_cache(maxsize=256)  # noqa: B019 - one World per scenario, kept for the process's life
    def _field(self, row: int, col: int) -> np.ndarray:
        assert self.graph is not None, "no distance field in the open world"
        return distance_fields(self.passable, [(row, col)], self.scenario.cell, self.graph)[0]

    @functools.cached_property
    def across(self) -> float:
        """How far a robot may have to drive to cross its reachable space: the domain's diagonal in the open
        world, else the geodesic diameter of the reachable cells (a double sweep: the farthest cell from the
        first reachable one, then the farthest from that)."""
        if self.open:
            return float(np.hypot(*self.scenario.domain))
        start = np.argwhere(self.reachable)[0]
        first = self._field(int(start[0]), int(start[1]))
        far = np.unravel_index(int(np.argmax(np.where(np.isfinite(first) & self.reachable, first, -1.0))), first.shape)
        second = self._field(int(far[0]), int(far[1]))
        return float(np.max(np.where(np.isfinite(second) & self.reachable, second, 0.0)))

    def summary(self) -> dict[str, object]:
        """What summary.json reports of the terrain."""
        report: dict[str, object] = {
            "unreachable_cells": self.unreachable_cells,
            "coverable_cells": int(self.coverable.sum()),
            "occupied_cells": int(self.occupied.sum()),
        }
        if unsure := int(self.unsure.sum()):  # asked of the truth, not of the noisy team (coverage_map_of)
            report["unsure_cells"] = unsure
        if self.map_sha256:
            report["map_sha256"] = self.map_sha256
        if self.priority_sha256:
            report["priority_sha256"] = self.priority_sha256
        frame = map_frame_of(self.scenario)
        # trajectory.csv is in the map's frame: the model's (0, 0) is at map_corner, its x axis at map_yaw.
        if frame.corner != (0.0, 0.0):
            report["map_corner"] = list(frame.corner)
        if frame.yaw != 0.0:
            report["map_yaw"] = frame.yaw
        return report


def viewing_range_of(scenario: Scenario) -> float:
    """How near a cell must lie to a reachable cell's centre, in clear sight, to count as coverable (and to be
    a viewpoint of it): R less a cell, never under R/2 (eq. 10's stop). A robot sent to a cell stops anywhere
    within half a cell of its centre (and, once looking, stays within three quarters: model.world.wall_law),
    and eq. 2's α falls to 0 at R: on the lab map of issue 34 a cell seen only from 1.4998 of R = 1.5 held a
    single robot, looking at it, for 15,000 time units. At R less a cell, α ≥ α_max·(cell/4)/R wherever the
    robot stands (aimed at the cell)."""
    return max(scenario.range - scenario.cell, 0.5 * scenario.range)


FINE_WALL_MARGIN = 0.5
"""Clearance, in cells, that paths and straight drives keep beyond the planning margin where walls are finer
than the cell (:func:`plan_radius_of`): half a cell, how far from a cell's centre a robot sent there stops
(model.world.wall_law). On whole cells a passable centre's disk is clear of whole wall cells, and the real
wall lies up to a cell beyond; to the pixel, a centre that only just held the disk put robots among the
campus map's outdoor speckle, where the law and the filter dithered between the specks: 6 of 30 single
robots completed (issue 34, 2026-12-06). Seeds 0 - 3 with 0.45 of a cell: all four; with a quarter: three.
The study with half a cell (docs/real-maps.md): 26 of 30 single robots, every team of 4 and 8."""


def plan_radius_of(scenario: Scenario, fine_walls: bool = False) -> float:
    """The robot's radius plus the planning margin: what passable cells and straight drives keep free.
    With the safety filter on, its margin too: the filter keeps the disk s off every wall (model.safety.safety),
    so a path nearer a wall than that would be one the filter stops the robot on. With walls finer than the
    cell (``fine_walls``), FINE_WALL_MARGIN more."""
    return wall_clearance_of(scenario) + (PLANNING_MARGIN + (FINE_WALL_MARGIN if fine_walls else 0.0)) * scenario.cell


def wall_clearance_of(scenario: Scenario) -> float:
    """How near a wall the robot's centre comes: r, plus the safety margin when the filter is on."""
    return scenario.robot_radius + (safety_margin_of(scenario) if scenario.filters else 0.0)


def team_space(passable: np.ndarray, cell: float, graph: csr_matrix | None = None) -> np.ndarray:
    """The largest component of passable cells in ``graph`` (else :func:`grid_graph`'s 8-connected one; see the
    module's docstring)."""
    if not passable.any():
        return passable.copy()
    _, labels = connected_components(grid_graph(passable, cell) if graph is None else graph, directed=False)
    labels = labels.reshape(passable.shape)
    sizes = np.bincount(labels[passable])
    return passable & (labels == int(np.argmax(sizes)))


def _priority_ticks(scenario: Scenario, shape: tuple[int, int]) -> tuple[np.ndarray, str]:
    high = round(scenario.lambda_star * COVERAGE_SCALE)
    if not scenario.priority_map:
        return np.full(shape, high, dtype=np.int64), ""
    image = cv2.imread(scenario.priority_map, cv2.IMREAD_GRAYSCALE)
    if image is None or image.size == 0:
        raise TerrainError(f"scenario key 'lambda_star': {scenario.priority_map} is not a PGM or PNG image")
    rows, cols = shape
    grey = cv2.resize(np.flipud(image), (cols, rows), interpolation=cv2.INTER_AREA).astype(np.float64) / 255.0
    low = round(scenario.lambda_star_min * COVERAGE_SCALE)
    return np.rint(low + grey * (high - low)).astype(np.int64), file_sha256(Path(scenario.priority_map))


@functools.lru_cache(maxsize=8)
def fitted_map_of(scenario: Scenario) -> tuple[OccupancyMap, FittedMap]:
    """The scenario's map as read, and fitted to its cells (:mod:`model.scenario.map_fit`)."""
    occupancy_map = load_map(scenario.map)
    return occupancy_map, fit_to_cells(occupancy_map, scenario.cell)


def map_frame_of(scenario: Scenario) -> MapFrame:
    """Where the model's frame lies in the map's own (REP 105's ``map``): its (0, 0) and x axis; the model's
    own frame without a map."""
    return fitted_map_of(scenario)[1].frame if scenario.map else MapFrame()


def map_note_of(scenario: Scenario) -> str | None:
    """What fitting the map to the cells changed (cropped, padded), for the console; None if nothing."""
    if not scenario.map:
        return None
    occupancy_map, fitted = fitted_map_of(scenario)
    return fitted.note(occupancy_map)


MAX_GRAIN_SPLIT = 5
"""At most this many wall squares a cell side (25 a cell). A map's walls are kept to its pixel where that
fits, else to the largest whole number of pixels that divides the cell into at most this many: 0.04 m on
the lab map's 0.2 m cells, 0.16 m on the campus's 0.8 m. Fitted to whole cells instead, a one-pixel wall
thickened to a cell on each side it touched: on the campus, doors and corridors under about 3.8 m closed,
and 4,735 free cells (3,030 m², 42 % of the free space) counted as unreachable (issue 34). Finer costs
time in every disk test and every build: a 0.08 m grain took 100 s to build the campus's world."""


GAP_WIDTH = 0.1
"""A gap in a wall narrower than this (in the map's units), and at least a pixel, is filled (:func:`closed_gaps`)."""


def closed_gaps(pixels: np.ndarray, resolution: float) -> np.ndarray:
    """The map's not-free pixels with every gap in a wall narrower than GAP_WIDTH (one pixel at least) filled:
    a run of free pixels, across or up and down, with not-free pixels at both ends, as a crack in a wall or the
    rim of a pillar the laser saw in pieces is. A camera would look through it, and no robot fits through it:
    kept to the pixel, walls let cells inside the lab map's round pillars count as coverable, seen through
    gaps of 1 - 2 pixels (4 - 8 cm) in the rims. Nothing else changes: a free run that reaches the image's
    edge, or is as wide as GAP_WIDTH, stays free; diagonal gaps are left to the line of sight's own corner
    rule (model.world.visibility)."""
    longest = max(1, math.ceil(GAP_WIDTH / resolution - 1e-9) - 1)  # pixels: a run this long or shorter is a gap
    return pixels | _short_runs(pixels, longest) | _short_runs(pixels.T, longest).T


@njit(cache=True)
def _short_runs(walls: np.ndarray, longest: int) -> np.ndarray:
    """The free pixels of each row that lie in a run of at most ``longest`` with a wall pixel at both ends."""
    rows, cols = walls.shape
    short = np.zeros((rows, cols), dtype=np.bool_)
    for row in range(rows):
        last_wall = -1  # the column of the last wall pixel seen in this row
        for col in range(cols):
            if not walls[row, col]:
                continue
            if last_wall >= 0 and 0 < col - last_wall - 1 <= longest:
                short[row, last_wall + 1 : col] = True
            last_wall = col
    return short


def grain_split_of(pixels: np.ndarray, factor: int) -> int:
    """Wall squares a cell side for a fitted map's ``pixels`` (``factor`` a cell side): the largest divisor of
    ``factor`` up to MAX_GRAIN_SPLIT, or 1 when every cell is wholly wall or wholly free at that split (walls
    drawn on whole cells: nothing to gain, and the world is the one fitted to cells)."""
    split = max(d for d in range(1, min(factor, MAX_GRAIN_SPLIT) + 1) if factor % d == 0)
    if split == 1:
        return 1
    squares = coarsen(pixels, factor // split)
    blocks = squares.reshape(squares.shape[0] // split, split, squares.shape[1] // split, split)
    return 1 if bool((blocks.all(axis=(1, 3)) == blocks.any(axis=(1, 3))).all()) else split


def _wall_grid(scenario: Scenario) -> tuple[np.ndarray, int, str]:
    """(the wall squares, squares a cell side, the map's SHA-256) of a scenario with terrain."""
    rows, cols = scenario.grid_shape
    split, sha = 1, ""
    walls = np.zeros((rows, cols), dtype=bool)
    if scenario.map:
        occupancy_map, fitted = fitted_map_of(scenario)
        pixels = closed_gaps(fitted.occupied, fitted.resolution) if scenario.wall_detail == "map" else fitted.occupied
        split = grain_split_of(pixels, fitted.factor) if scenario.wall_detail == "map" else 1
        walls = coarsen(pixels, fitted.factor // split)
        sha = occupancy_map.sha256
    if scenario.obstacles:
        # Given in the map's frame, as poses are; the model's frame moves with the crop and turns with the yaw.
        frame = map_frame_of(scenario)
        polygons = [
            np.stack(frame.from_map(*np.array(polygon, dtype=np.float64).T), axis=1) for polygon in scenario.obstacles
        ]
        walls |= polygons_on_grid(polygons, rows * split, cols * split, scenario.cell / split)
    return walls, split, sha


@functools.lru_cache(maxsize=8)
def world_of(scenario: Scenario) -> World:
    """The scenario's world, built once per process (it is pure: same scenario, same world).
    Raises TerrainError when no robot fits anywhere."""
    shape, cell = scenario.grid_shape, scenario.cell
    targets, priority_sha = _priority_ticks(scenario, shape)
    if not scenario.has_terrain:
        everywhere = np.ones(shape, dtype=bool)
        nowhere = ~everywhere
        return World(
            scenario, nowhere, nowhere, cell, everywhere, None, everywhere, everywhere, targets, "", priority_sha
        )
    wall_grid, split, map_sha = _wall_grid(scenario)
    grain = cell if split == 1 else cell / split
    occupied = coarsen(wall_grid, split)
    where = f"the map {scenario.map}" if scenario.map else "the domain"
    if occupied.all():
        raise TerrainError(f"{where} has no free cell")
    bounded = bool(scenario.map)
    plan_radius = plan_radius_of(scenario, split > 1)
    passable = passable_cells(wall_grid, plan_radius, cell, bounded, grain, shape)
    graph = passage_graph(passable, cell, wall_grid, grain, plan_radius, bounded).tocsr()
    reachable = team_space(passable, cell, graph)
    if not reachable.any():
        raise TerrainError(f"{where}: no free place holds a robot of radius {scenario.robot_radius}")
    start = tuple(int(v) for v in np.argwhere(reachable)[0])
    coverable = coverable_cells(wall_grid, passable, [start], viewing_range_of(scenario), cell, grain, graph)
    return World(
        scenario, occupied, wall_grid, grain, passable, graph, reachable, coverable, targets, map_sha, priority_sha
    )
