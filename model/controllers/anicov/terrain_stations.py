"""anicov's stations among walls, and what their programme says this sensor can do on a map (issue 36,
items 1 and 6; docs/controller.md).

- **Where a robot can stand**: the serpentine grid's points (:func:`model.controllers.anicov.stations.grid`,
  at the layout's spacing), each moved to the centre of the reachable cell nearest it (the disk with its
  clearance and planning margin fits there: :mod:`model.world.world`), dropped where none lies within half
  the spacing or another point took that cell.
- **What a stare sees**: one plan period of the engine's own sensor at a station and bearing, past the walls
  of the world's ground (:class:`model.controllers.anicov.deposit.Deposit`), occlusion included where the
  scenario has it.
- **Cells no station sees** get a station of their own: while a coverable cell lies outside every stare,
  the reachable cell nearest it that sees it (:func:`model.world.reachability.seers`, the rule that defines
  coverable) joins the stations. A cell still unseen then is reported (:attr:`Programme.unseen`), never
  dropped silently.
- **The programme**: the least periods of stares that bring every coverable cell to Λ*, relaxed (periods
  need not be whole) and with the hops left out (no order among walls is chosen here): its stare time,
  divided by N, is the time this sensor needs on this map from these stations if the stares were shared
  perfectly and nobody travelled (``anicov bound`` prints it). On the open square it sits beside t*_N
  (docs/controller.md has both).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog
from scipy.sparse import csc_matrix, hstack
from scipy.spatial import cKDTree

from model.controllers.anicov.deposit import Deposit
from model.controllers.anicov.route import CARROT_PERIOD
from model.controllers.anicov.stations import BEARINGS, MARGIN_PER_RANGE, SPACINGS_PER_RANGE, grid
from model.scenario import Scenario
from model.world.world import World, world_of

ANGLES = 2.0 * math.pi * np.arange(BEARINGS) / BEARINGS


@dataclass(frozen=True)
class Programme:
    """The stations among walls (K, 2), their relaxed periods (K, BEARINGS), the coverable cells no stare
    reaches, the stares' total time (time units), and the programme itself: the stares of the coverable cells
    some stare reaches (rows: those cells' flat indices; columns: station by station, bearing by bearing)."""

    stations: np.ndarray
    periods: np.ndarray
    unseen: int
    stare_time: float
    stares: csc_matrix
    rows: np.ndarray


def stations_among_walls(world: World, spacing: float) -> np.ndarray:
    """The grid's points at most ``spacing`` apart, each at the centre of the reachable cell nearest it (K, 2),
    in the grid's serpentine order; a point with no reachable cell within half the spacing, or whose cell an
    earlier point took, is left out."""
    scenario = world.scenario
    width, height = scenario.domain
    points = grid(width, height, spacing, MARGIN_PER_RANGE * scenario.range, False)
    cells = np.argwhere(world.reachable)
    if not len(cells):
        return np.zeros((0, 2))
    centres = (cells[:, ::-1] + 0.5) * scenario.cell
    gaps, nearest = cKDTree(centres).query(points)
    taken: set[int] = set()
    kept = []
    for gap, index in zip(gaps, nearest, strict=True):
        if gap <= 0.5 * spacing and int(index) not in taken:
            taken.add(int(index))
            kept.append(centres[index])
    return np.array(kept).reshape(-1, 2)


def programme_among_walls(scenario: Scenario) -> Programme:
    """The stations and their relaxed programme on the scenario's map (:class:`Programme`), at whichever of
    :data:`SPACINGS_PER_RANGE` needs the least stare time; computed once per domain and sensor."""
    return _programme(_keyed(scenario))


def _keyed(scenario: Scenario) -> Scenario:
    """The scenario with the team, seed and time limit set aside (they do not change the programme), as
    :func:`model.controllers.anicov.stations.layout` keys its layouts."""
    return dataclasses.replace(scenario, agents=1, seed=0, max_time=1.0)


def deposit_among_walls(scenario: Scenario) -> Deposit:
    """What a stare of a carrot period adds past the scenario's walls (:class:`Deposit`), one per domain and sensor
    in a process: the programme, the tour's hops and the flight's patches and cleanups share the legs and sure
    stares it keeps (pure results, so sharing them changes nothing but the time)."""
    return _deposit(_keyed(scenario))


@functools.lru_cache(maxsize=8)
def _deposit(scenario: Scenario) -> Deposit:
    return Deposit(scenario, world_of(scenario).ground, round(CARROT_PERIOD / scenario.dt))


@functools.cache
def _programme(scenario: Scenario) -> Programme:
    world = world_of(scenario)
    options = [_solved(world, share * scenario.range) for share in SPACINGS_PER_RANGE]
    return min(options, key=lambda programme: (programme.unseen, programme.stare_time))


def _solved(world: World, spacing: float) -> Programme:
    """The programme at one spacing: the stations, those added for cells no stare reached, and HiGHS's
    relaxed periods."""
    scenario = world.scenario
    deposit = deposit_among_walls(scenario)
    stations = stations_among_walls(world, spacing)
    stares = deposit.stares(stations, ANGLES)
    coverable = world.coverable.ravel()
    stations, stares, unseen = _with_stations_for_unseen(world, deposit, stations, stares)
    rows = np.flatnonzero(coverable & (np.asarray(stares.sum(axis=1)).ravel() > 0.0))
    demand = stares.tocsr()[rows]
    solved = linprog(np.ones(demand.shape[1]), A_ub=-demand, b_ub=-np.ones(len(rows)), bounds=(0, None), method="highs")
    if solved.x is None:
        raise ValueError(f"the stations' programme has no solution: {solved.message}")
    periods = solved.x.reshape(len(stations), BEARINGS)
    return Programme(stations, periods, unseen, float(periods.sum()) * CARROT_PERIOD, demand.tocsc(), rows)


def _with_stations_for_unseen(
    world: World, deposit: Deposit, stations: np.ndarray, stares: csc_matrix
) -> tuple[np.ndarray, csc_matrix, int]:
    """(stations, stares, cells still unseen): while a coverable cell (the first in row order) lies outside
    every stare, the nearest reachable cell that sees it joins the stations; a cell that even its own seer's
    stares miss is counted and passed over."""
    cell = world.scenario.cell
    cols = world.coverable.shape[1]
    seen = np.asarray(stares.sum(axis=1)).ravel() > 0.0
    waiting = np.flatnonzero(world.coverable.ravel() & ~seen)
    added, blocks, unseen = [], [stares], 0
    while len(waiting):
        row, col = divmod(int(waiting[0]), cols)
        found = world.seers_of((col + 0.5) * cell, (row + 0.5) * cell)
        if len(found):
            station = found[:1, 1:]
            more = deposit.stares(station, ANGLES)
            added.append(station)
            blocks.append(more)
            seen |= np.asarray(more.sum(axis=1)).ravel() > 0.0
        if not seen[waiting[0]]:
            unseen += 1
            seen[waiting[0]] = True  # passed over: reported, not tried again
        waiting = waiting[~seen[waiting]]
    return np.vstack([stations.reshape(-1, 2), *added]), hstack(blocks).tocsc(), unseen
