"""The ``anicov`` controller's planner: a spiral at the sensor's best spacing, orbits over what it will leave,
then passes over what is left.

Beyond the paper (docs/controller.md has the measurements and the reasons). What the runs of the
paper's law show: a robot stands R/2 from a blob's centroid and stares at it (eq. 10), and a camera
whose ability α (eq. 2) is five times Λ* at its apex wastes most of what it senses while standing; a
straight pass at full speed wastes least. So:

1. **A spiral.** A rectangular spiral inward (:func:`model.controllers.anicov.routes.spiral_path`), its rings evenly
   spaced at most :func:`model.controllers.anicov.routes.best_lane_spacing` apart (from eq. 2: the widest spacing at
   which two neighbouring passes at k_v still bring the point midway to Λ*), the outer ring d100 inside
   the edges, the innermost d100 from the centre line; or, where the robots weave their heading and
   that flies the spiral sooner (:mod:`model.controllers.anicov.weave`, on the paper's sensor), at the weave's spacing and
   reach. Lanes back and forth need a run-up of about R
   outside the domain at every lane's start (a forward camera sees a point beside a lane only from
   behind it); a spiral needs one.
2. **Pieces.** The spiral is cut into N pieces, flown inward (flown outward, a ring's corners leave
   gaps no later ring closes), the first entered :func:`model.controllers.anicov.routes.lead_in` before the spiral's
   start, the others where the piece before them ends (its robot's camera covered ahead of that end).
   Robots take pieces by the assignment that minimises the longest transit, then the total
   (:func:`model.controllers.anicov.routes.bottleneck_assignment` on scipy's ``linear_sum_assignment``), and the pieces
   are resized until transit, run-up and flight take every robot about as long
   (:func:`model.controllers.anicov.routes.balanced_routes`): the team finishes with its slowest robot. The robot whose
   piece ends at the centre gets less spiral, to take the passes the small innermost ring leaves there.
   On the 2 of the spiral's 8 symmetries (which corner it starts from, which way it turns) that finish
   soonest so, the order in which robots take pieces is then improved by local search and the pieces cut
   exactly for it (:mod:`model.controllers.anicov.piece_order`); the sooner is flown. Pieces after the first are entered
   2 units back along the spiral, and a robot starting near the spiral's start gets twice the run-up.
3. **Touch-ups.** The routes are flown once here, as the engine will fly them
   (:func:`model.controllers.anicov.touch_ups.simulate_routes`), and every group of cells they will leave short gets an
   orbit, a small circle whose forward camera sweeps all around it, appended to the route of the robot
   that will finish it soonest (:func:`model.controllers.anicov.touch_ups.with_touch_ups`; a team of one leaves its route
   for it and comes back). An orbit whose cells are covered by the time its robot gets there is skipped.
4. **Passes.** A robot done with its piece takes the uncovered blobs in turns (cells with Υ > 0 within
   a lane spacing of each other, leaving out the strips robots still on their piece will sweep): the
   assignment of free robots to blobs minimises their total distance, and a pass runs along the blob's
   major axis through its centroid, from its nearer end (or from before it, to make the pass at least
   :func:`model.controllers.anicov.routes.lead_in` long).

The planner speaks the paper's messages: every CARROT_PERIOD (model.controllers.anicov.route) it gives each robot one
objective, a point :data:`LOOKAHEAD` ahead of it along its path (pure pursuit's carrot); the robot
drives toward it with :func:`model.paper.control.pursuit_law`. Same interface as
:class:`model.planning.Planner`, so the engine and the coordinator run either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

from model.controllers.anicov.route import (
    CARROT_PERIOD,
    FACE_RADIUS,
    Route,
    Stop,
    arrive_radius_of,
    face_radius_of,
)
from model.controllers.anicov.routes import balanced_routes, lead_in
from model.controllers.anicov.stations import station_routes, with_patched_stops
from model.controllers.anicov.terrain_flight import TerrainFlight
from model.controllers.anicov.terrain_lanes import terrain_routes
from model.controllers.anicov.touch_ups import TouchUp, blob_labels, with_touch_ups
from model.controllers.anicov.weave import sweep_of
from model.paper.objectives import BlobObjectives
from model.parameters import starting_poses
from model.planning import TeamPlanner
from model.scenario import Scenario

LOOKAHEAD = 2.0
"""Distance ahead along the path at which the carrot is put (units)."""
STARE_DISTANCE = 0.25
"""With stations, how far from a blob's centroid a robot stands to stare at it (a share of R)."""
STARE_PERIODS = 2
"""With stations, plan periods a robot stares at a blob before the blobs are dealt out again."""


def blob_passes(
    lack: np.ndarray, cell: float, lead: float, spacing: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every uncovered blob as a pass along its major axis through its centroid: (M, 2, 2, 2) the two
    ways to fly it, each (entry at its near end, or before it so that the pass is at least ``lead``
    long: a forward camera sees a small blob only from some way off; exit at its far end); (M, 2) the
    centroids; the blob labels of the grid. A blob: the cells with Υ > 0 that lie closer than a lane spacing to
    each other (8-connected once grown by half a spacing), so that the scraps a row of lanes leaves
    along an edge make one pass along it, not one each."""
    count, labels = blob_labels(lack > 0.0, cell, spacing)
    ways, centres = [], []
    for k in range(1, count):
        rows, cols = np.nonzero(labels == k)
        if len(rows) == 0:
            continue
        points = np.stack([(cols + 0.5) * cell, (rows + 0.5) * cell], axis=1)
        centre = points.mean(axis=0)
        spread = points - centre
        axis = np.linalg.eigh(spread.T @ spread)[1][:, -1] if len(points) > 1 else np.array([1.0, 0.0])
        extent = spread @ axis
        low, high = centre + extent.min() * axis, centre + extent.max() * axis
        run_up = max(0.0, lead - float(extent.max() - extent.min()))  # a pass is at least ``lead`` long
        ways.append([[low - run_up * axis, high], [high + run_up * axis, low]])
        centres.append(centre)
    return np.array(ways).reshape(-1, 2, 2, 2), np.array(centres).reshape(-1, 2), labels


@dataclass
class LanePlanner(TeamPlanner):
    """The ``anicov`` controller's planning (see the module): one carrot per robot per call."""

    replayed = True  # the first plan cuts every robot's route; later ones advance, patch and clean up

    scenario: Scenario
    blobs: BlobObjectives = field(default_factory=BlobObjectives)
    routes: dict[int, Route] = field(default_factory=dict)
    touch_ups: dict[int, list[TouchUp]] = field(default_factory=dict)
    stared: dict[int, np.ndarray] = field(default_factory=dict)  # stations: each robot's last stare (x, y, Σ Υ)

    def __post_init__(self) -> None:
        self.terrain = self.scenario.has_terrain
        # Among walls no pass is flown (the weave's sweep is the open square's), and a strip is a range wide.
        self.sweep = None if self.terrain else sweep_of(self.scenario)
        self.lead = 0.0 if self.terrain else lead_in(self.scenario, self.spacing)
        # Among walls, at the robot's own units: a carrot two plan periods of travel ahead.
        self.lookahead = 2.0 * CARROT_PERIOD * self.scenario.k_v if self.terrain else LOOKAHEAD
        self.flight = TerrainFlight(self.scenario) if self.terrain else None

    @property
    def spacing(self) -> float:
        """The rings' spacing (:attr:`model.controllers.anicov.weave.Sweep.spacing`); among walls, R."""
        return self.scenario.range if self.sweep is None else self.sweep.spacing

    def plan(self, lack: np.ndarray, positions: np.ndarray, members: list[int] | None = None) -> np.ndarray:
        """A carrot (x, y) for every member (default all, in id order), shape (M, 2)."""
        ids = list(range(len(positions))) if members is None else list(members)
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
        if not self.routes:
            start = self._all(ids, positions)
            stops: list[list[Stop]] | None = None
            flown = None
            if self.terrain:
                routes, stops = terrain_routes(self.scenario, start)
            elif self.scenario.stations:
                routes, stops, _ = station_routes(self.scenario, start)
                stops, flown = with_patched_stops(self.scenario, routes, stops, start, LOOKAHEAD)
            else:
                sweep = self.sweep
                assert sweep is not None
                routes = balanced_routes(
                    self.scenario, sweep.spacing, start, self.lead, sweep.reach, sweep.edge, sweep.centre_leads
                )
            if self.terrain:  # the foresight flies the open world: among walls what is left is met as it comes
                touch_ups: list[list[TouchUp]] = [[] for _ in routes]
            else:
                routes, touch_ups = with_touch_ups(self.scenario, routes, start, LOOKAHEAD, self.spacing, stops, flown)
            for agent, route in zip(range(self.scenario.agents), routes, strict=True):
                self.routes[agent] = Route.of(route, stops=None if stops is None else stops[agent])
                self.touch_ups[agent] = touch_ups[agent]
        window = self.lookahead  # no robot is past the carrot it was given (it slows to stop on it)
        free = []
        for index, agent in enumerate(ids):
            route = self.routes[agent]
            self._skip_done_touch_ups(agent, lack)
            route.advance(positions[index], window)
            if route.done():
                free.append(index)
        if self.flight is not None:
            self.flight.steer(self.routes, lack, positions, ids, free)
        elif free:
            self._give_passes(lack, positions, ids, free)
        face, arrive = face_radius_of(self.scenario), arrive_radius_of(self.scenario)
        held = {} if self.flight is None else self.flight.held  # robots waiting their turn at a station
        targets = np.array(
            [
                held[agent]
                if agent in held
                else self.routes[agent].carrot(positions[index], self.lookahead, face, arrive)
                for index, agent in enumerate(ids)
            ],
            dtype=np.float64,
        )
        return targets.reshape(-1, 2)

    def _skip_done_touch_ups(self, agent: int, lack: np.ndarray) -> None:
        """A touch-up (:mod:`model.controllers.anicov.touch_ups`) whose cells are all covered by the time its robot's carrot
        reaches it is skipped: foretold from the planned routes alone, a spot may be covered by then (by a
        pass, or by a robot whose start heading was not the one foretold). One flown already is forgotten."""
        route, waiting = self.routes[agent], self.touch_ups.get(agent, [])
        while waiting and (
            waiting[0].end <= route.progress
            or (waiting[0].start <= route.progress + LOOKAHEAD and not (lack[waiting[0].spot] > 0.0).any())
        ):
            route.progress = max(route.progress, waiting.pop(0).end)

    def _strip_cells(self) -> int:
        """The width, in cells, of the strip a route sweeps: a lane spacing, half of it each side."""
        return max(1, round(self.spacing / self.scenario.cell))

    def _all(self, ids: list[int], positions: np.ndarray) -> np.ndarray:
        """Every robot's position at the first plan; a robot not among the members (planning = "local", out of
        radio contact) at its seeded start pose, so that every robot cuts the same routes for the team."""
        where = starting_poses(self.scenario)[:, :2].copy()  # among walls: clear of them (free_initial_poses)
        for index, agent in enumerate(ids):
            where[agent] = positions[index]
        return where

    def _give_passes(self, lack: np.ndarray, positions: np.ndarray, ids: list[int], free: list[int]) -> None:
        """Robots done with their route take a pass each over the uncovered blobs, by least total
        distance to the passes' entries; a robot left without one stays where it is."""
        # A pass is entered at the blob's near end, with a run-up only to make it ``lead`` long: measured,
        # finishing sooner than a full run-up (``lead``) before every pass (N = 10: 3.10 t* against 3.29;
        # again on 2026-12-03, 8 seeds: 2.88 against 3.07); a pass of length 0 over a small blob would
        # park the robot on it, unseen by its forward camera, for ever.
        ways, centres, labels = blob_passes(self._unclaimed(lack, ids), self.scenario.cell, self.lead, self.spacing)
        self.blobs = BlobObjectives(centres, labels.astype(np.int32))
        for index in free:  # stay, unless given a pass below
            self.routes[ids[index]] = Route.of(positions[index][None, :], cleanup=True)
        if not len(ways):
            return
        distance = np.linalg.norm(positions[free][:, None, None, :] - ways[None, :, :, 0, :], axis=3)  # (F, M, 2)
        robots, chosen = linear_sum_assignment(distance.min(axis=2))
        for robot, blob in zip(robots, chosen, strict=True):
            index = free[robot]
            if self.scenario.stations and self._may_stare(ids[index], positions[index], centres[blob], lack):
                continue
            entry, exit_ = ways[blob, int(np.argmin(distance[robot, blob]))]
            self.routes[ids[index]] = Route.of(np.array([positions[index], entry, exit_]), cleanup=True)

    def _may_stare(self, agent: int, position: np.ndarray, centre: np.ndarray, lack: np.ndarray) -> bool:
        """Give ``agent`` a stare at the blob about ``centre`` (:meth:`_stare_at`), unless it would be the
        stare it was given last, from the same place, and nothing was covered since: what a blob's remnant
        can leave (two scraps at its ends, their centroid the same, out of the wedge's sides) would then keep
        it staring for ever; it flies the blob's pass instead (False)."""
        route = self._stare_at(position, centre)
        stand, total = route.point_at(route.length), float(lack.sum())
        last = self.stared.get(agent)
        if last is not None and float(np.linalg.norm(stand - last[:2])) < FACE_RADIUS and total >= last[2]:
            return False
        self.stared[agent] = np.array([stand[0], stand[1], total])
        self.routes[agent] = route
        return True

    def _stare_at(self, position: np.ndarray, centre: np.ndarray) -> Route:
        """With stations (:mod:`model.controllers.anicov.stations`), a robot's turn at a blob: it stands :data:`STARE_DISTANCE`
        R from the blob's centroid on its own side and faces the centroid for
        :data:`STARE_PERIODS` plan periods; a blob left after that gets another turn."""
        away = position - centre
        gap = float(np.linalg.norm(away))
        distance = STARE_DISTANCE * self.scenario.range
        side = away / gap if gap > 1e-9 else np.array([1.0, 0.0])  # a camera never sees what it stands on
        stand = centre + side * distance
        bearing = math.atan2(centre[1] - stand[1], centre[0] - stand[0])
        points = np.array([position, stand])
        length = float(np.linalg.norm(stand - position))
        return Route.of(points, cleanup=True, stops=[Stop(length, [bearing] * STARE_PERIODS)])

    def _unclaimed(self, lack: np.ndarray, ids: list[int]) -> np.ndarray:
        """Υ without the strips that robots still on their route will sweep (half a spacing each side of
        what is left of it), so that a robot done early does not fly another's lanes before it."""
        claimed = np.zeros(lack.shape, dtype=np.uint8)
        cell = self.scenario.cell
        width = self._strip_cells()
        for agent in ids:
            route = self.routes[agent]
            if route.cleanup or route.done():
                continue
            route.draw_ahead(claimed, cell, width)
        return np.where(claimed.astype(bool), 0.0, lack)
