"""The ``anicov`` controller's routes: the robot's polyline and its progress, the spiral at the sensor's best
spacing, its pieces and who flies which.

Beyond the paper (docs/controller.md has the measurements and the reasons; :mod:`model.controllers.anicov.lane_planner` is
the planner that gives the carrots along these routes):

- :func:`best_lane_spacing`: from eq. 2, the widest spacing at which two neighbouring passes at k_v still
  bring the point midway to Λ*; :func:`lead_in`: how far before a lane a forward camera must start.
- :func:`spiral_path`: a rectangular spiral inward, its rings evenly spaced at most that spacing apart,
  the outer ring d100 inside the edges (or a weaving sweep's spacing, reach and edge:
  :func:`model.controllers.anicov.weave.sweep_of`); :func:`spiral_variants`: the same in the domain's 8 symmetries.
- :func:`balanced_routes`: the spiral cut into N pieces flown inward, robots assigned to pieces by the
  least longest transit (:func:`bottleneck_assignment` on scipy's ``linear_sum_assignment``), the pieces
  resized until every robot finishes together, on the symmetry that finishes first; then the order in
  which robots take pieces improved and the pieces cut again for it (:mod:`model.controllers.anicov.piece_order`).
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
from scipy.optimize import linear_sum_assignment, minimize_scalar

from model.controllers.anicov.order_search import improved_order
from model.controllers.anicov.piece_order import Spiral, cuts_for, run_up_entries, start_run_ups
from model.controllers.anicov.route import Route
from model.paper.metrics import pass_reach, straight_pass_coverage
from model.paper.polyline import path_between
from model.scenario import Scenario

BALANCING_ROUNDS = 10
"""Rounds of resizing the pieces so that every robot finishes together (balanced_routes)."""
MIN_PIECE = 0.2
"""No piece shorter than this share of an equal one (a robot far from everything still flies some)."""
CENTRE_ALLOWANCE_LEADS = 8.0
"""Run-ups of extra work counted for the robot whose piece ends at the spiral's centre (balanced_routes)."""
TIE = 1e-9
"""Estimated finishes (units) closer than this are a tie: the first candidate stays."""
SEAM_OVERLAP = 2.0
"""How far back along the spiral from its cut a piece after the first is entered (units): the carrot's
distance (:data:`model.controllers.anicov.lane_planner.LOOKAHEAD`), in which a robot arriving at an angle turns onto the
spiral. Entered at the cut itself, a seam left a few cells a few per cent short, and at N = 30 on the
200 x 50 strip (8 seeds) their orbits cost the team more than the overlap: 18.6 groups of such cells
against 2.8, 2.02 t* against 1.95."""
ORDERED_VARIANTS = 2
"""Of the spiral's 8 symmetries, how many (the soonest after resizing) have their order improved
(:mod:`model.controllers.anicov.piece_order`): all 8 were within 0.01 t* of the best 2 at N = 4 - 30 (8 seeds), at four
times the planning time."""


def best_lane_spacing(scenario: Scenario) -> float:
    """The lane spacing s that covers most area per unit time, from eq. 2 (Fig. 7's straight pass).

    Two neighbouring passes at speed v bring the point midway between them Λ = 2 C(s/2) / v, C the
    one-pass coverage at speed 1 (:func:`model.paper.metrics.straight_pass_coverage`; the midpoint is the
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


def spiral_path(
    scenario: Scenario, spacing: float, reach: float | None = None, edge: float | None = None
) -> np.ndarray:
    """The one-robot sweep: a rectangular spiral inward, as a polyline (K, 2). Its outer ring lies ``edge``
    inside the domain's edges; its rings are evenly spaced, at most ``spacing`` apart, so that the
    innermost one is at most ``reach`` from the domain's centre line (one pass brings Λ* that far): a
    spiral whose last ring stopped short would leave its centre to slow passes after it. ``reach`` and
    ``edge`` default to d100, a straight pass's (:func:`model.controllers.anicov.weave.sweep_of` gives a weave's)."""
    width, height = scenario.domain
    reach = pass_reach(scenario) if reach is None else reach
    return spiral_in(width, height, reach, spacing, edge)  # edge None: spiral_in puts the outer ring at the reach


def spiral_in(width: float, height: float, reach: float, spacing: float, edge: float | None = None) -> np.ndarray:
    """:func:`spiral_path` of a ``width`` x ``height`` rectangle whose one pass brings Λ* ``reach`` aside (a
    straight pass's d100), the outer ring ``edge`` (default ``reach``) inside its edges."""
    first = min(reach if edge is None else edge, width / 2.0, height / 2.0)
    innermost = min(reach, width / 2.0, height / 2.0)
    inward = min(width, height) / 2.0 - (first + innermost)  # from the outer ring to where the innermost may be
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


def spiral_variants(
    scenario: Scenario, spacing: float, reach: float | None = None, edge: float | None = None
) -> list[np.ndarray]:
    """:func:`spiral_path` in each of the domain rectangle's 8 symmetries (started from each corner, either
    way round): the same rings, flown inward, their starts in other places, each ending where the spiral
    does (on the innermost ring)."""
    width, height = scenario.domain
    reach = pass_reach(scenario) if reach is None else reach
    along_x = spiral_in(width, height, reach, spacing, edge)
    along_y = spiral_in(height, width, reach, spacing, edge)[:, ::-1]  # the transposed rectangle's, transposed back
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


def balanced_routes(
    scenario: Scenario,
    spacing: float,
    positions: np.ndarray,
    lead: float,
    reach: float | None = None,
    edge: float | None = None,
    centre_leads: float = CENTRE_ALLOWANCE_LEADS,
) -> list[np.ndarray]:
    """Each robot's route, its piece sized so that the team finishes together. Every one of the spiral's 8
    symmetries (:func:`spiral_variants`) has its pieces resized (:func:`balanced_routes_on`): at random
    starts, the bottleneck transit depends on where the spiral starts and which way it turns (measured, 4
    seeds: N = 4 2.76 -> 2.67 t*, N = 30 3.78 -> 3.58). On the :data:`ORDERED_VARIANTS` that finish
    soonest so (the first on a tie), the order in which robots take pieces is improved and the pieces cut
    again for it (:func:`ordered_routes`), and the sooner is flown. A robot alone flies the soonest.
    ``reach`` and ``edge`` place the rings (:func:`spiral_path`; default d100), ``centre_leads`` is the
    centre's allowance in run-ups (:func:`balanced_routes_on`): a weaving sweep's (:func:`model.controllers.anicov.weave.
    sweep_of`) differ from a straight pass's."""
    tried = []
    for path in spiral_variants(scenario, spacing, reach, edge):
        routes, finish, owners = balanced_routes_on(scenario, path, positions, lead, centre_leads)
        tried.append((finish, path, routes, owners))
    soonest = sorted(range(len(tried)), key=lambda k: tried[k][0])  # stable: the first on a tie
    if scenario.agents == 1 or Route.of(tried[soonest[0]][1]).length <= 0.0:  # alone, or a spiral of one point
        return tried[soonest[0]][2]
    best, best_finish = None, math.inf
    for k in soonest[:ORDERED_VARIANTS]:
        _, path, _, owners = tried[k]
        routes, finish = ordered_routes(scenario, path, positions, lead, np.array(owners), centre_leads)
        if finish < best_finish - TIE:
            best, best_finish = routes, finish
    assert best is not None
    return best


def ordered_routes(
    scenario: Scenario,
    spiral: np.ndarray,
    positions: np.ndarray,
    lead: float,
    order: np.ndarray,
    centre_leads: float = CENTRE_ALLOWANCE_LEADS,
) -> tuple[list[np.ndarray], float]:
    """Routes on ``spiral`` for a team (N > 1) with the best order near ``order``
    (:func:`model.controllers.anicov.order_search.improved_order`) and its finish: the pieces cut so that each takes its robot
    the same time, each after the first entered :data:`SEAM_OVERLAP` back along the spiral. A robot left
    without a piece (its transit alone too long, or after the spiral's end is reached) has a route of its
    own position and takes passes from the start; one sharing the centre's allowance
    (:mod:`model.controllers.anicov.piece_order`) has a route to the spiral's end. The centre's allowance is ``centre_leads``
    run-ups (:func:`balanced_routes_on`)."""
    whole = Route.of(spiral)
    cut_on = Spiral(whole.points, whole.along, lead, centre_leads * lead, SEAM_OVERLAP)
    order, finish = improved_order(order, positions, cut_on)
    routes = [positions[robot][None, :].copy() for robot in range(len(positions))]
    for robot, start, end in cuts_for(order, finish, positions, cut_on):
        piece = path_between(whole.points, cut_on.entered(start) if start > 0.0 else 0.0, end)
        if start == 0.0:
            piece = with_run_up(piece, float(start_run_ups(positions[robot], whole.points[0], lead)))
        routes[robot] = np.vstack([positions[robot][None, :], piece])
    return routes, finish


def balanced_routes_on(
    scenario: Scenario,
    spiral: np.ndarray,
    positions: np.ndarray,
    lead: float,
    centre_leads: float = CENTRE_ALLOWANCE_LEADS,
) -> tuple[list[np.ndarray], float, list[int]]:
    """Routes on ``spiral``, their estimated finish and each piece's robot, in the spiral's order (a robot
    alone flies these routes; for a team they are where :func:`ordered_routes` starts, and its routes are
    flown). From equal pieces, each round assigns robots to pieces (:func:`assign_pieces`), then moves every
    piece's length halfway to the one that makes transit, run-up and flight the same for all; the routes
    with the earliest estimated finish (longest transit + run-up + piece) are kept (the first on a
    near-tie). The last piece, which ends on the spiral's innermost ring, counts ``centre_leads`` run-ups
    more (:data:`CENTRE_ALLOWANCE_LEADS` for straight passes; a weave's,
    :data:`model.controllers.anicov.weave.WEAVE_CENTRE_LEADS`): on a square that ring's sides are shorter than a run-up and
    it leaves part of the centre to passes (on the paper's square at N = 1: three, 70 time units), which its
    robot, near them, takes while the others finish (4 seeds, with the 8 symmetries: N = 2 2.56 -> 2.47 t*,
    N = 4 2.67 -> 2.63, N = 10 3.11 -> 2.86; without it the team waited for one robot's passes at the
    centre). Measured on the 200 x 50 strip too, whose innermost ring is long and thin (4 seeds): N = 10
    1.82 -> 1.78 t*, within 0.01 at N = 1, 4 and 30."""
    whole = Route.of(spiral)
    total = whole.length
    if total <= 0.0:  # a domain within 2·d100 on both sides: one point, every robot goes there
        return [np.vstack([position, whole.points[:1]]) for position in positions], 0.0, list(range(len(positions)))
    lengths = np.full(scenario.agents, total / scenario.agents)
    allowance = np.zeros(scenario.agents)
    allowance[-1] = centre_leads * lead if scenario.agents > 1 else 0.0
    best, best_finish, best_owners = None, math.inf, []
    for _ in range(BALANCING_ROUNDS + 1):
        cuts = np.concatenate([[0.0], np.cumsum(lengths)])
        cuts[-1] = total
        pieces = cut(whole, cuts)
        routes, owners = assign_pieces(pieces, positions, lead, with_owners=True)
        run_ups = np.zeros(len(pieces))  # the spiral's start only (assign_pieces)
        run_ups[0] = start_run_ups(positions[owners[0]], whole.points[0], lead)
        transit = (
            allowance
            + run_ups
            + np.array([np.linalg.norm(routes[owners[k]][1] - positions[owners[k]]) for k in range(len(pieces))])
        )
        finish = float(np.max(transit + lengths))
        if finish < best_finish - TIE:
            best, best_finish, best_owners = routes, finish, owners
        target = np.maximum((total + transit.sum()) / scenario.agents - transit, MIN_PIECE * total / scenario.agents)
        lengths = 0.5 * lengths + 0.5 * target / target.sum() * total
    assert best is not None
    return best, best_finish, best_owners


def with_run_up(piece: np.ndarray, lead: float) -> np.ndarray:
    """A piece entered ``lead`` before its first point, along its first stretch (the camera looks ahead)."""
    return np.vstack([run_up_entries(piece, lead), piece])


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
    ``lead`` before its first point (twice that for a robot starting near it: :func:`start_run_ups`); the
    others start where the piece before them ends: a point beside the spiral just past a seam is seen by the
    camera of the robot ending there from behind, as a run-up would (measured, 8 seeds, without a run-up at
    the seams: N = 4 2.65 -> 2.61 t*, N = 10 2.98 -> 2.88, N = 30 3.59 -> 3.41). Pieces are flown the way
    the spiral goes (inward: flown outward, a ring's corners leave gaps the next ring does not close); the
    assignment minimises the longest transit, then the total. ``with_owners``: also each piece's robot."""
    run_ups = start_run_ups(positions, pieces[0][0], lead)  # the first piece's, each robot's own
    transit = np.array([[np.linalg.norm(piece[0] - p) for piece in pieces] for p in positions])
    transit[:, 0] = np.linalg.norm(run_up_entries(pieces[0], run_ups) - positions, axis=1)
    robots, chosen = bottleneck_assignment(transit)
    routes: list[np.ndarray] = [np.zeros((0, 2))] * len(positions)
    owners = [0] * len(pieces)
    for robot, piece in zip(robots, chosen, strict=True):
        entry = with_run_up(pieces[0], float(run_ups[robot])) if piece == 0 else pieces[piece]
        routes[robot] = np.vstack([positions[robot][None, :], entry])
        owners[piece] = int(robot)
    return (routes, owners) if with_owners else routes
