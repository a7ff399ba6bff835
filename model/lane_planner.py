"""The ``anicov`` controller's planner: a spiral at the sensor's best spacing, then passes over what is left.

Beyond the paper (docs/controller.md has the measurements and the reasons). What the runs of the
paper's law show: a robot stands R/2 from a blob's centroid and stares at it (eq. 10), and a camera
whose ability α (eq. 2) is five times Λ* at its apex wastes most of what it senses while standing; a
straight pass at full speed wastes least. So:

1. **A spiral.** A rectangular spiral inward (:func:`spiral_path`), its rings evenly spaced at most
   :func:`best_lane_spacing` apart (from eq. 2: the widest spacing at which two neighbouring passes at
   k_v still bring the point midway to Λ*), the outer ring d100 inside the edges, the innermost d100
   from the centre line. Lanes back and forth need a run-up of about R outside the domain at every
   lane's start (a forward camera sees a point beside a lane only from behind it); a spiral needs one.
2. **Pieces.** The spiral is cut into N pieces, flown inward (flown outward, a ring's corners leave
   gaps no later ring closes), the first entered :func:`lead_in` before the spiral's start, the others
   where the piece before them ends (its robot's camera covered ahead of that end). Robots take pieces
   by the assignment that minimises the longest transit, then the total (:func:`bottleneck_assignment`
   on scipy's ``linear_sum_assignment``), and the pieces are resized until transit, run-up and flight
   take every robot about as long (:func:`balanced_routes`): the team finishes with its slowest robot.
   The robot whose piece ends at the centre gets less spiral, to take the passes the small innermost
   ring leaves there; and of the spiral's 8 symmetries (which corner it starts from, which way it
   turns) the one that finishes soonest is flown.
3. **Passes.** A robot done with its piece takes the uncovered blobs in turns (cells with Υ > 0 within
   a lane spacing of each other, leaving out the strips robots still on their piece will sweep): the
   assignment of free robots to blobs minimises their total distance, and a pass runs along the blob's
   major axis through its centroid, from its nearer end (or from before it, to make the pass at least
   :func:`lead_in` long).

The planner speaks the paper's messages: every CARROT_PERIOD (model.scenario) it gives each robot one
objective, a point :data:`LOOKAHEAD` ahead of it along its path (pure pursuit's carrot); the robot
drives toward it with :func:`model.control.pursuit_law`. Same interface as
:class:`model.planning.Planner`, so the engine and the coordinator run either.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import cv2
import numpy as np
from scipy.optimize import linear_sum_assignment, minimize_scalar

from model.metrics import coverage_distance, straight_pass_coverage
from model.objectives import BlobObjectives
from model.scenario import Scenario
from model.zigzag import path_between, point_along

Plan = tuple[int, tuple[int, ...], np.ndarray, np.ndarray, np.ndarray | None]

LOOKAHEAD = 2.0
"""Distance ahead along the path at which the carrot is put (units)."""
BALANCING_ROUNDS = 10
"""Rounds of resizing the pieces so that every robot finishes together (balanced_routes)."""
MIN_PIECE = 0.2
"""No piece shorter than this share of an equal one (a robot far from everything still flies some)."""
CENTRE_ALLOWANCE_LEADS = 8.0
"""Run-ups of extra work counted for the robot whose piece ends at the spiral's centre (balanced_routes)."""


def best_lane_spacing(scenario: Scenario) -> float:
    """The lane spacing s that covers most area per unit time, from eq. 2 (Fig. 7's straight pass).

    Two neighbouring passes at speed v bring the point midway between them Λ = 2 C(s/2) / v, C the
    one-pass coverage at speed 1 (:func:`model.metrics.straight_pass_coverage`; the midpoint is the
    least covered point between them, C being convex). The fastest speed that still reaches Λ* is
    v(s) = min(k_v, 2 C(s/2) / Λ*), and the area swept per unit time s·v(s) is largest at the returned s.
    """

    def rate(spacing: float) -> float:
        midway = straight_pass_coverage(spacing / 2.0, scenario.range, scenario.half_angle, scenario.alpha_max)
        return -spacing * min(scenario.k_v, 2.0 * midway / scenario.lambda_star)

    reach = 2.0 * scenario.range * math.sin(scenario.half_angle)
    found = minimize_scalar(rate, bounds=(1e-3 * reach, reach), method="bounded", options={"xatol": 1e-6})
    return float(found.x)


def lead_in(scenario: Scenario, spacing: float) -> float:
    """How far before a lane's first point the robot enters it: a point half a spacing beside the lane
    comes into the wedge (half angle F) only once the robot is (s/2)/tan F behind it."""
    return min(scenario.range, spacing / 2.0 / math.tan(scenario.half_angle))


@dataclass
class Route:
    """A robot's polyline and how far along it (arc length) the robot has come."""

    points: np.ndarray  # (K, 2)
    along: np.ndarray  # (K,) cumulative arc length
    progress: float = 0.0
    cleanup: bool = False  # a pass over a blob (True) or the robot's piece of the lanes

    @classmethod
    def of(cls, points: np.ndarray, cleanup: bool = False) -> Route:
        points = np.asarray(points, dtype=np.float64)
        keep = np.concatenate([[True], np.linalg.norm(np.diff(points, axis=0), axis=1) > 1e-9])
        points = points[keep]
        along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
        return cls(points, along, 0.0, cleanup)

    @property
    def length(self) -> float:
        return float(self.along[-1])

    def point_at(self, distance: float) -> np.ndarray:
        """The point ``distance`` along the route, held to its ends."""
        if len(self.points) == 1:
            return self.points[0].copy()
        return point_along(self.points, self.along, min(max(distance, 0.0), self.length))

    def advance(self, position: np.ndarray, window: float) -> None:
        """Progress := the nearest point of the route to ``position`` at most ``window`` ahead of where
        it was: no farther than the carrot the robot was given (so a neighbouring ring is never taken,
        nor, on a pass that doubles back over a small blob, the way back while it is still going out);
        the first such along the route on a tie."""
        reach = self.progress + window
        best, best_distance = self.progress, math.inf
        for k in range(len(self.points) - 1):
            start, end = self.along[k], self.along[k + 1]
            if end < self.progress or start > reach:
                continue
            at = min(max(self._foot(k, position), self.progress), reach)
            gap = float(np.linalg.norm(self.point_at(at) - position))
            if gap < best_distance - 1e-9:
                best, best_distance = at, gap
        self.progress = max(self.progress, best)

    def done(self) -> bool:
        return self.progress >= self.length - 1e-6

    def nearest(self, position: np.ndarray) -> tuple[float, float]:
        """(distance, arc length) of the route's point nearest to ``position``, the first on a tie."""
        if len(self.points) == 1:
            return float(np.linalg.norm(self.points[0] - position)), 0.0
        best_gap, best_at = math.inf, 0.0
        for k in range(len(self.points) - 1):
            at = self._foot(k, position)
            gap = float(np.linalg.norm(self.point_at(at) - position))
            if gap < best_gap - 1e-9:
                best_gap, best_at = gap, at
        return best_gap, best_at

    def _foot(self, k: int, position: np.ndarray) -> float:
        """Arc length of the point of segment k nearest to ``position``."""
        a, b = self.points[k], self.points[k + 1]
        d = b - a
        span2 = float(d @ d)
        t = 0.0 if span2 == 0.0 else float(np.clip((position - a) @ d / span2, 0.0, 1.0))
        return float(self.along[k] + t * (self.along[k + 1] - self.along[k]))

    def draw_ahead(self, canvas: np.ndarray, cell: float, width: int) -> None:
        """Draw what is left of the route (from its progress on) into ``canvas`` (uint8 grid), ``width``
        cells wide."""
        ahead = self.points[self.along > self.progress]
        line = np.vstack([self.point_at(self.progress), ahead]) / cell
        cv2.polylines(canvas, [np.round(line).astype(np.int32)], False, 1, thickness=width)


def spiral_path(scenario: Scenario, spacing: float) -> np.ndarray:
    """The one-robot sweep: a rectangular spiral inward, as a polyline (K, 2). Its outer ring lies d100
    inside the domain's edges; its rings are evenly spaced, at most ``spacing`` apart, so that the
    innermost one is at most d100 from the domain's centre line (one pass brings Λ* that far): a
    spiral whose last ring stopped short would leave its centre to slow passes after it."""
    width, height = scenario.domain
    d100 = coverage_distance(scenario.lambda_star, scenario.range, scenario.half_angle, scenario.alpha_max)
    first = min(d100, width / 2.0, height / 2.0)
    inward = min(width, height) / 2.0 - 2.0 * first  # from the outer ring to where the innermost may be
    rings = max(0, math.ceil(inward / spacing - 1e-9))
    step = inward / rings if rings else 0.0
    points: list[tuple[float, float]] = []
    for ring in range(rings + 1):
        left, bottom = first + ring * step, first + ring * step
        right, top = width - left, height - bottom
        if ring < rings:
            points += [(left, bottom), (right, bottom), (right, top), (left, top), (left, bottom + step)]
        elif top - bottom > 1e-9 and right - left > 1e-9:
            points += [(left, bottom), (right, bottom), (right, top), (left, top), (left, bottom)]
        else:  # the innermost ring is a line along the longer side
            points += [(left, bottom), (right, top)]
    return np.array(points, dtype=np.float64)


def spiral_pieces(scenario: Scenario, spacing: float) -> list[np.ndarray]:
    """The spiral cut into N pieces of equal length (polylines), one per robot."""
    whole = Route.of(spiral_path(scenario, spacing))
    return cut(whole, np.linspace(0.0, whole.length, scenario.agents + 1))


def cut(whole: Route, cuts: np.ndarray) -> list[np.ndarray]:
    """A route cut at ``cuts`` (arc lengths from 0 to its length) into consecutive polylines."""
    return [path_between(whole.points, low, high) for low, high in itertools.pairwise(cuts)]


def spiral_variants(scenario: Scenario, spacing: float) -> list[np.ndarray]:
    """:func:`spiral_path` in each of the domain rectangle's 8 symmetries (started from each corner, either
    way round): the same rings, flown inward, their starts in other places."""
    width, height = scenario.domain
    along_x = spiral_path(scenario, spacing)
    along_y = spiral_path(scenario.with_overrides(domain=[height, width]), spacing)[:, ::-1]  # transposed
    variants = []
    for path in (along_x, along_y):
        for flip_x, flip_y in itertools.product((False, True), repeat=2):
            variant = np.array(path, dtype=np.float64)
            if flip_x:
                variant[:, 0] = width - variant[:, 0]
            if flip_y:
                variant[:, 1] = height - variant[:, 1]
            variants.append(variant)
    return variants


def balanced_routes(scenario: Scenario, spacing: float, positions: np.ndarray, lead: float) -> list[np.ndarray]:
    """Each robot's route, its piece sized so that the team finishes together, on whichever of the
    spiral's 8 symmetries (:func:`spiral_variants`) gives the earliest estimated finish (the first on a
    tie): at random starts, the bottleneck transit depends on where the spiral starts and which way it
    turns (measured, 4 seeds: N = 4 2.76 -> 2.67 t*, N = 30 3.78 -> 3.58)."""
    best, best_finish = None, math.inf
    for path in spiral_variants(scenario, spacing):
        routes, finish = balanced_routes_on(scenario, path, positions, lead)
        if finish < best_finish:
            best, best_finish = routes, finish
    assert best is not None
    return best


def balanced_routes_on(
    scenario: Scenario, spiral: np.ndarray, positions: np.ndarray, lead: float
) -> tuple[list[np.ndarray], float]:
    """Routes on ``spiral`` and their estimated finish. From equal pieces, each round assigns robots to
    pieces (:func:`assign_pieces`), then moves every piece's length halfway to the one that makes
    transit, run-up and flight the same for all; the routes with the earliest estimated finish (longest
    transit + run-up + piece) are kept. The piece that ends at the centre counts
    :data:`CENTRE_ALLOWANCE_LEADS` run-ups more: the innermost ring, its sides shorter than a run-up on a
    square, leaves part of the centre to passes (on the paper's square at N = 1: three, 70 time units),
    and its robot, near them, takes them while the others finish (measured, 8 seeds: N = 10 3.11 -> 2.88
    t*; none: the team waited for one robot's passes at the centre)."""
    whole = Route.of(spiral)
    total = whole.length
    if total <= 0.0:  # a domain within 2·d100 on both sides: one point, every robot goes there
        return [np.vstack([position, whole.points[:1]]) for position in positions], 0.0
    lengths = np.full(scenario.agents, total / scenario.agents)
    allowance = np.zeros(scenario.agents)
    allowance[-1] = CENTRE_ALLOWANCE_LEADS * lead if scenario.agents > 1 else 0.0
    best, best_finish = None, math.inf
    for _ in range(BALANCING_ROUNDS + 1):
        cuts = np.concatenate([[0.0], np.cumsum(lengths)])
        cuts[-1] = total
        pieces = cut(whole, cuts)
        routes, owners = assign_pieces(pieces, positions, lead, with_owners=True)
        run_ups = np.where(np.arange(len(pieces)) == 0, lead, 0.0)  # the spiral's start only (assign_pieces)
        transit = (
            allowance
            + run_ups
            + np.array([np.linalg.norm(routes[owners[k]][1] - positions[owners[k]]) for k in range(len(pieces))])
        )
        finish = float(np.max(transit + lengths))
        if finish < best_finish:
            best, best_finish = routes, finish
        target = np.maximum((total + transit.sum()) / scenario.agents - transit, MIN_PIECE * total / scenario.agents)
        lengths = 0.5 * lengths + 0.5 * target / target.sum() * total
    assert best is not None
    return best, best_finish


def with_run_up(piece: np.ndarray, lead: float) -> np.ndarray:
    """A piece entered ``lead`` before its first point, along its first stretch (the camera looks ahead)."""
    direction = piece[1] - piece[0]
    direction = direction / max(float(np.linalg.norm(direction)), 1e-300)
    return np.vstack([piece[0] - lead * direction, piece])


def bottleneck_assignment(cost: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows to columns (square ``cost``) minimising the largest cost taken, then the total among those
    (the team finishes when its slowest robot does): the least threshold that still admits a perfect
    matching, found by bisection over the costs, then linear_sum_assignment within it."""
    values = np.unique(cost)
    low, high = 0, len(values) - 1
    while low < high:
        middle = (low + high) // 2
        allowed = (cost <= values[middle]).astype(np.float64)
        rows, cols = linear_sum_assignment(-allowed)
        if allowed[rows, cols].sum() == len(cost):
            high = middle
        else:
            low = middle + 1
    capped = np.where(cost <= values[low], cost, cost.max() * len(cost) + 1.0)
    return linear_sum_assignment(capped)


def assign_pieces(pieces: list[np.ndarray], positions: np.ndarray, lead: float, with_owners: bool = False) -> Any:
    """Each robot's route: its start, then its piece. The first piece (the spiral's start) is entered
    ``lead`` before its first point; the others start where the piece before them ends: a point beside
    the spiral just past a seam is seen by the camera of the robot ending there from behind, as a run-up
    would (measured, 8 seeds, without a run-up at the seams: N = 4 2.65 -> 2.61 t*, N = 10 2.98 -> 2.88,
    N = 30 3.59 -> 3.41). Pieces are flown the way the spiral goes (inward: flown outward, a ring's
    corners leave gaps the next ring does not close); the assignment minimises the longest transit,
    then the total. ``with_owners``: also each piece's robot."""
    entries = [with_run_up(piece, lead) if k == 0 else piece for k, piece in enumerate(pieces)]
    transit = np.array([[np.linalg.norm(route[0] - p) for route in entries] for p in positions])
    robots, chosen = bottleneck_assignment(transit)
    routes: list[np.ndarray] = [np.zeros((0, 2))] * len(positions)
    owners = [0] * len(pieces)
    for robot, piece in zip(robots, chosen, strict=True):
        routes[robot] = np.vstack([positions[robot][None, :], entries[piece]])
        owners[piece] = int(robot)
    return (routes, owners) if with_owners else routes


def blob_passes(
    lack: np.ndarray, cell: float, lead: float, spacing: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every uncovered blob as a pass along its major axis through its centroid: (M, 2, 2, 2) the two
    ways to fly it, each (entry at its near end, or before it so that the pass is at least ``lead``
    long: a forward camera sees a small blob only from some way off; exit at its far end); (M, 2) the
    centroids; the blob labels of the grid. A blob: the cells with Υ > 0 that lie closer than a lane spacing to
    each other (8-connected once grown by half a spacing), so that the scraps a row of lanes leaves
    along an edge make one pass along it, not one each."""
    uncovered = (lack > 0.0).astype(np.uint8)
    reach = max(1, round(spacing / 2.0 / cell))
    grown = cv2.dilate(uncovered, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * reach + 1, 2 * reach + 1)))
    count, labels = cv2.connectedComponents(grown, connectivity=8)
    labels = labels * uncovered
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
class LanePlanner:
    """The ``anicov`` controller's planning (see the module): one carrot per robot per call."""

    scenario: Scenario
    blobs: BlobObjectives = field(default_factory=BlobObjectives)
    routes: dict[int, Route] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.spacing = best_lane_spacing(self.scenario)
        self.lead = lead_in(self.scenario, self.spacing)

    def plan(self, lack: np.ndarray, positions: np.ndarray, members: list[int] | None = None) -> np.ndarray:
        """A carrot (x, y) for every member (default all, in id order), shape (M, 2)."""
        ids = list(range(len(positions))) if members is None else list(members)
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
        if not self.routes:
            routes = balanced_routes(self.scenario, self.spacing, self._all(ids, positions), self.lead)
            for agent, route in zip(range(self.scenario.agents), routes, strict=True):
                self.routes[agent] = Route.of(route)
        window = LOOKAHEAD  # no robot is past the carrot it was given (it slows to stop on it)
        free = []
        for index, agent in enumerate(ids):
            route = self.routes[agent]
            route.advance(positions[index], window)
            if route.done():
                free.append(index)
        if free:
            self._give_passes(lack, positions, ids, free)
        targets = np.array(
            [self.routes[agent].point_at(self.routes[agent].progress + LOOKAHEAD) for agent in ids], dtype=np.float64
        )
        return targets.reshape(-1, 2)

    def resume(self, lack: np.ndarray, positions: np.ndarray, members: list[int]) -> None:
        """A planner rebuilt after its coordinator was lost in realtime, its routes cut again at a first
        plan on the robots' starting positions (as the lost one cut them): each robot is put at the nearest
        point of its route, and its route is done if it stands farther than half a spacing from it (it was
        on a pass) or nothing uncovered lies within half a spacing of what is left of it (it had flown
        it), so that the next plan gives it a pass instead of flying covered ground again."""
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
        for index, agent in enumerate(members):
            route = self.routes.get(agent)
            if route is None or route.cleanup:
                continue
            gap, at = route.nearest(positions[index])
            route.progress = at
            if gap > self.spacing / 2.0 or not self._left_to_cover(lack, route):
                route.progress = route.length

    def _left_to_cover(self, lack: np.ndarray, route: Route) -> bool:
        """Whether an uncovered cell lies within half a spacing of the route from its progress on."""
        strip = np.zeros(lack.shape, dtype=np.uint8)
        route.draw_ahead(strip, self.scenario.cell, max(1, round(self.spacing / self.scenario.cell)))
        return bool((lack[strip.astype(bool)] > 0.0).any())

    def _all(self, ids: list[int], positions: np.ndarray) -> np.ndarray:
        """Every robot's position at the first plan (a robot not among the members: the domain's centre)."""
        where = np.tile(np.array(self.scenario.domain) / 2.0, (self.scenario.agents, 1))
        for index, agent in enumerate(ids):
            where[agent] = positions[index]
        return where

    def _give_passes(self, lack: np.ndarray, positions: np.ndarray, ids: list[int], free: list[int]) -> None:
        """Robots done with their route take a pass each over the uncovered blobs, by least total
        distance to the passes' entries; a robot left without one stays where it is."""
        # A pass is entered at the blob's near end, with a run-up only to make it ``lead`` long: measured,
        # finishing sooner than the pieces' run-up before every pass (N = 10: 3.10 t* against 3.29); a pass
        # of length 0 over a small blob would park the robot on it, unseen by its forward camera, for ever.
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
            entry, exit_ = ways[blob, int(np.argmin(distance[robot, blob]))]
            self.routes[ids[index]] = Route.of(np.array([positions[index], entry, exit_]), cleanup=True)

    def _unclaimed(self, lack: np.ndarray, ids: list[int]) -> np.ndarray:
        """Υ without the strips that robots still on their route will sweep (half a spacing each side of
        what is left of it), so that a robot done early does not fly another's lanes before it."""
        claimed = np.zeros(lack.shape, dtype=np.uint8)
        cell = self.scenario.cell
        width = max(1, round(self.spacing / cell))
        for agent in ids:
            route = self.routes[agent]
            if route.cleanup or route.done():
                continue
            route.draw_ahead(claimed, cell, width)
        return np.where(claimed.astype(bool), 0.0, lack)

    def labels(self) -> np.ndarray | None:
        return None if self.blobs.labels is None else self.blobs.labels.astype(np.uint16)

    def record(self, step: int, targets: np.ndarray) -> Plan:
        return (step, tuple(range(len(targets))), targets.copy(), self.blobs.positions.copy(), self.labels())
