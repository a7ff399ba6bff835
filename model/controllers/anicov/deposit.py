"""What a camera adds to the coverage map (eq. 2-3) from poses the planner chooses: a stare from a station, a
straight hop between stations, a leg of a route; the stations' linear programmes
(:mod:`model.controllers.anicov.stations`, :mod:`model.controllers.anicov.terrain_plan`) are built from them.

Beyond the paper (docs/controller.md). Each is one step of the engine's own sensor
(:func:`model.world.wedge.sense_wedge_among`, in the open world or past the walls of a given ground), so that
what the programme counts is what the engine would add.
"""

from __future__ import annotations

import itertools
import math
from typing import Any, TypeVar

import numpy as np
from numba import njit
from scipy.sparse import csc_matrix, hstack

from model.paper.coverage_map import CoverageMap, add_window
from model.scenario import Scenario
from model.scenario.physics_keys import cover_margin_of, sure_doubt_of
from model.world.ground import Ground, open_ground
from model.world.wedge import sense_wedge_among

T = TypeVar("T")

LEGS_KEPT = 4096
"""The legs :meth:`Deposit.leg_cells` keeps (the oldest goes first)."""

SURE_STATIONS_KEPT = 4096
"""The stations whose sure stares :meth:`Deposit.sure_stares` keeps (the oldest goes first). The campus at N = 8
asks 3,981 stations' sure stares in its cleanups and patches, 567 of them different: kept, its run takes 36 s
of wall clock instead of 45."""


@njit(cache=True)
def _cells_of(
    window: np.ndarray, row0: int, col0: int, width: int, period_steps: int, target_ticks: int
) -> tuple[np.ndarray, np.ndarray]:
    """The window's non-zero cells in row-major order, as flat indices of a grid ``width`` wide, and each one's
    ticks times ``period_steps`` over ``target_ticks``: what ``np.nonzero`` and indexing gave, in one call (the
    campus at N = 1 asks half a million stares; the Python around the kernel cost as much as the kernel)."""
    count = 0
    for value in window.ravel():
        count += value != 0
    flat, added = np.empty(count, dtype=np.int64), np.empty(count, dtype=np.float64)
    k = 0
    for row in range(window.shape[0]):
        for col in range(window.shape[1]):
            value = window[row, col]
            if value != 0:
                flat[k] = (row + row0) * width + col + col0
                added[k] = (value * period_steps) / target_ticks
                k += 1
    return flat, added


def _kept(store: dict[Any, T], key: Any, value: T, most: int) -> T:
    """``value``, kept in ``store`` under ``key``; the oldest kept goes first when ``most`` are."""
    if len(store) >= most:
        store.pop(next(iter(store)), None)
    store[key] = value
    return value


class Deposit:
    """The coverage a camera adds over the scenario's grid, as the engine's sensor adds it, in the team map's units:
    Λ*, or (1 + cover_margin) Λ* with noise; "in Λ*" below means in those units."""

    def __init__(self, scenario: Scenario, ground: Ground | None = None, period_steps: int | None = None) -> None:
        """``ground``: the world's, for stares that walls hide (the open world's if not given); ``period_steps``:
        the steps of one stare (the scenario's plan period if not given)."""
        self.scenario = scenario
        self.period_steps = scenario.plan_steps if period_steps is None else period_steps
        self.shape = scenario.grid_shape
        # In the units of the team's map, which asks (1 + cover_margin) Λ* with noise (model.parameters): a stare
        # counted in Λ* there over-counts by the margin, and every station left its cells that much short (the
        # paper's square, N = 10, the noise: cleanups of 400 - 700 short cells, 188.0 time units against
        # 145.4 kinematic).
        margin = cover_margin_of(scenario)
        self.target_ticks = CoverageMap(*self.shape, scenario.cell, scenario.lambda_star * (1.0 + margin)).target_ticks
        self.ground, self.nobody = open_ground() if ground is None else ground, np.zeros((0, 2))
        self.blank = np.zeros(self.shape, dtype=np.int64)  # the map the sensor reads Υ from (not written)
        self.doubt = sure_doubt_of(scenario)  # a robot unsure of its pose counts only what it surely sees
        self._legs: dict[tuple[float, float, float, float], tuple[np.ndarray, np.ndarray]] = {}
        self._sure: dict[tuple[float, float, float, bytes], csc_matrix] = {}

    def window(self, x: float, y: float, theta: float) -> tuple[int, int, np.ndarray]:
        """(row0, col0, ticks) one step of the sensor adds from this pose."""
        scenario = self.scenario
        _, _, _, row0, col0, window = sense_wedge_among(
            self.blank, 1 << 62, x, y, theta, scenario.range, scenario.half_angle,
            scenario.alpha_max, scenario.dt, scenario.cell, self.ground, self.nobody, self.doubt,
        )  # fmt: skip
        return row0, col0, window

    def stare_cells(self, x: float, y: float, theta: float) -> tuple[np.ndarray, np.ndarray]:
        """One plan period facing ``theta`` from (x, y): (flat indices of the cells it reaches, Λ* added to
        each). The robot stands still, so every step of the period adds the same window."""
        row0, col0, window = self.window(x, y, theta)
        return _cells_of(window, row0, col0, self.shape[1], self.period_steps, self.target_ticks)

    def stare(self, x: float, y: float, theta: float) -> np.ndarray:
        """One plan period facing ``theta`` from (x, y), per cell (Λ*)."""
        flat, added = self.stare_cells(x, y, theta)
        cells = np.zeros(self.shape[0] * self.shape[1])
        cells[flat] = added
        return cells

    def stares(self, stations: np.ndarray, angles: np.ndarray) -> csc_matrix:
        """Every station's stare at every angle (cells x stations·angles, Λ*), built sparse: a stare reaches
        a wedge's cells of the domain's."""
        indices, values, starts = [np.zeros(0, dtype=np.int64)], [np.zeros(0)], [0]  # none at all: an empty matrix
        for x, y in stations:
            for angle in angles:
                flat, added = self.stare_cells(float(x), float(y), float(angle))
                indices.append(flat)
                values.append(added)
                starts.append(starts[-1] + len(flat))
        shape = (self.shape[0] * self.shape[1], len(stations) * len(angles))
        return csc_matrix((np.concatenate(values), np.concatenate(indices), np.array(starts)), shape=shape)

    def sure_stares(self, stations: np.ndarray, angles: np.ndarray, spread: float) -> csc_matrix:
        """:meth:`stares`, each cell's the least of the station's and of the eight points ``spread`` from it
        (every 45°): a robot stands a little off its station (within the face radius), and a cell that a wall
        hides from one of those points may be hidden from where it stands. Each station's are kept for
        :data:`SURE_STATIONS_KEPT` stations (the cleanups ask the same candidates again and again)."""
        blocks = [self._sure_at(np.asarray(station, dtype=np.float64), angles, spread) for station in stations]
        if not blocks:
            return csc_matrix((self.shape[0] * self.shape[1], 0))
        return hstack(blocks, format="csc")

    def _sure_at(self, station: np.ndarray, angles: np.ndarray, spread: float) -> csc_matrix:
        """One station's sure stares (cells x angles), from the kept ones where they are."""
        key = (float(station[0]), float(station[1]), float(spread), np.asarray(angles, dtype=np.float64).tobytes())
        found = self._sure.get(key)
        if found is None:
            found = self.stares(station[None, :], angles)
            for way in np.arange(8) * math.pi / 4:
                shifted = station + spread * np.array([math.cos(way), math.sin(way)])
                found = found.minimum(self.stares(shifted[None, :], angles))
            found = _kept(self._sure, key, found.tocsc(), SURE_STATIONS_KEPT)
        return found

    def leg_cells(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One straight leg from ``a`` to ``b`` flown at k_v facing along it, as :meth:`hops` flies each hop:
        (flat indices of the cells it reaches, Λ* added to each). Kept for :data:`LEGS_KEPT` legs (a route's
        legs are asked for again at every patch and cleanup)."""
        key = (float(a[0]), float(a[1]), float(b[0]), float(b[1]))
        found = self._legs.get(key)
        if found is None:
            ticks = np.zeros(self.shape, dtype=np.int64)
            self._fly(ticks, np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64))
            flat = np.flatnonzero(ticks)
            found = _kept(self._legs, key, (flat, ticks.ravel()[flat] / self.target_ticks), LEGS_KEPT)
        return found

    def path(self, points: np.ndarray) -> np.ndarray:
        """A polyline's legs flown one after another (:meth:`leg_cells`), per cell (Λ*, flat)."""
        cells = np.zeros(self.shape[0] * self.shape[1])
        for a, b in itertools.pairwise(np.asarray(points, dtype=np.float64)):
            flat, added = self.leg_cells(a, b)
            cells[flat] += added
        return cells

    def _fly(self, ticks: np.ndarray, a: np.ndarray, b: np.ndarray) -> None:
        """Add to ``ticks`` the steps of the leg from ``a`` to ``b`` at k_v, facing along it (``b`` not reached)."""
        heading = math.atan2(b[1] - a[1], b[0] - a[0])
        steps = round(float(np.linalg.norm(b - a)) / (self.scenario.k_v * self.scenario.dt))
        for k in range(steps):
            x, y = a + (b - a) * k / steps
            row0, col0, window = self.window(float(x), float(y), heading)
            add_window(ticks, row0, col0, window, 1 << 62)

    def hops(self, stations: np.ndarray) -> np.ndarray:
        """The hops between consecutive stations flown straight at k_v, per cell (Λ*)."""
        ticks = np.zeros(self.shape, dtype=np.int64)
        for a, b in itertools.pairwise(stations):
            self._fly(ticks, a, b)
        return ticks.ravel() / self.target_ticks
