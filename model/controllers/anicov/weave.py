"""The ``anicov`` controller's passes: straight, or weaving, and how far apart their rings may lie.

Beyond the paper (docs/controller.md has the measurements). A straight pass at k_v pours most of what its
camera senses onto the line it flies: on the paper's sensor a point on that line gets 5 Λ* (eq. 2-3), one
half a spacing aside just Λ*/2, and lanes at the best spacing (:func:`model.controllers.anicov.routes.best_lane_spacing`,
7.73) sweep 7.73 area per time unit, 49 % of what the sensor could. A robot whose heading *weaves* about
its course, ±A in a sine of wavelength λ along the course, swings its wedge over the points beside it and
spreads the same ability over a wider band: at A = 0.45 rad two such passes bring Λ* to the point midway
between them 13.6 apart, at 0.90 of k_v forward, 12.2 area per time unit. The weave lives in the robot's
law (:func:`model.paper.control.pursuit_law`: the messages stay the paper's, one carrot per robot); this module
flies one such pass as the engine would (the law, the unicycle of eq. 1, carrots every plan period) and
reads its coverage profile across the course (eq. 2-3, at the least-covered phase of the weave), from
which the planner takes its rings' spacing, how close to the centre the innermost must come, and where the
outer ring lies, and which amplitude of :data:`AMPLITUDES`, straight (0) included, flies the domain's
spiral soonest (:func:`sweep_of`; A = 0.45 on the paper's square). On the 200 x 50 strip's sensor (R = 10)
no weave reaches as far alone as a straight pass does, and its passes stay straight.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from model.controllers.anicov.route import CARROT_PERIOD, Route
from model.controllers.anicov.routes import CENTRE_ALLOWANCE_LEADS, best_lane_spacing, spiral_in
from model.paper.control import pursuit_law
from model.paper.dynamics import unicycle_step
from model.paper.metrics import pass_reach
from model.paper.sensing import offset_from_heading, sensing_ability, wedge_reach
from model.scenario import Scenario

AMPLITUDES = (0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6)
"""Weave amplitudes tried (radians), besides straight passes. From 0.6 on the paper's sensor one pass no
longer brings its own course to Λ*."""
WAVELENGTH_PER_RANGE = 0.175
"""The weave's wavelength as a share of R (3.5 units on the paper's sensor): measured on the paper's
square, 2.5 - 5 units sweep within 3 % of each other; much longer ones leave gaps at some phases."""
MARGIN = 0.85
"""Weaving rings lie at most this share of the profile's limits apart (and from the centre): a weave's
coverage varies with its phase and round a ring's corners, and rings near the limit left cells a few per
cent short there, each an orbit's trip. The paper's square, 16 seeds, N = 1 / 4 / 10 / 30, the margin at
0.9: A = 0.4 with its rings 11.2 apart, 0.9 of its limit of 12.5, 2.056 / 2.256 / 2.351 / 2.733 t*; A = 0.45,
rings 11.1 apart at 0.82 of its 13.55, 1.932 / 2.044 / 2.234 / 2.694; A = 0.5 at 0.76 of 14.6, 1.945 / 2.062 /
2.299 / 2.766; as kept (A = 0.45, the margin at 0.85, rings 11.2 apart) 1.917 / 2.053 / 2.236 / 2.696;
three rings 13.7 apart at 0.94 of A = 0.5's limit (8 seeds): 2.31 / 2.45 / 2.73 / 2.81."""
LOOKAHEAD = 2.0
"""The carrot's distance ahead on the course (:data:`model.controllers.anicov.lane_planner.LOOKAHEAD`; a test holds them
equal)."""
WEAVE_CENTRE_LEADS = 2.0
"""The centre's allowance for weaving rings, in run-ups (:func:`model.controllers.anicov.routes.balanced_routes_on`; straight
passes count :data:`model.controllers.anicov.routes.CENTRE_ALLOWANCE_LEADS`, 8): a weave's innermost ring, 2 x its reach
across, leaves less of the centre, and its run-up is longer (11.3 on the paper's square, against 7.6).
Measured with A = 0.5 (16 seeds, N = 4 / 10 / 30): 1, 2, 3, 4, 4.7 and 8 run-ups give 2.070 / 2.286 / 2.751, 2.062 /
2.299 / 2.766, 2.069 / 2.313 / 2.784, 2.096 / 2.317 / 2.824, 2.115 / 2.325 / 2.807 and 2.174 / 2.392 / 2.887 t*."""
COURSE_STEPS_PER_UNIT = 1000
"""A cap on the steps of a simulated pass (at k_v = 1 and dt = 0.1 it takes about 10 a unit)."""
PHASES = 12
"""Points sampled along one wavelength of the course, for the least-covered phase."""
OFFSET_STEP = 0.05
"""Spacing (units) of the points sampled across the course."""


class PassLaw(NamedTuple):
    """What one pass's flight and coverage depend on: the sensor (eq. 2), Λ*, the law's gains, the time
    step and the steps between two carrots."""

    sensing_range: float
    half_angle: float
    alpha_max: float
    lambda_star: float
    k_v: float
    k_omega: float
    dt: float
    plan_steps: int

    @classmethod
    def of(cls, scenario: Scenario) -> PassLaw:
        """A scenario's, with the anicov controller's carrot period (:attr:`Scenario.plan_steps` reads the
        scenario's own controller; the sweep is the anicov controller's whatever the file names)."""
        return cls(
            scenario.range, scenario.half_angle, scenario.alpha_max, scenario.lambda_star, scenario.k_v,
            scenario.k_omega, scenario.dt, max(1, round(CARROT_PERIOD / scenario.dt)),
        )  # fmt: skip


@dataclass(frozen=True)
class Sweep:
    """How the anicov controller's robots sweep: the weave (amplitude 0: straight) and what the planner
    draws for it: rings at most ``spacing`` apart, the innermost within ``reach`` of the domain's centre
    line, the outer ring ``edge`` inside the domain's edges, the centre's allowance ``centre_leads``
    run-ups; ``forward``: the robot's speed along its course."""

    amplitude: float
    wavelength: float
    spacing: float
    reach: float
    edge: float
    forward: float
    centre_leads: float = CENTRE_ALLOWANCE_LEADS

    @property
    def rate(self) -> float:
        """Area brought to Λ* per time unit by passes ``spacing`` apart."""
        return self.spacing * self.forward


@functools.lru_cache(maxsize=64)
def sweep_of(scenario: Scenario) -> Sweep:
    """The sweep whose spiral (:func:`model.controllers.anicov.routes.spiral_in`) flies ``scenario``'s domain soonest: straight
    passes at :func:`model.controllers.anicov.routes.best_lane_spacing`, reaching d100 (eq. 2; the outer ring d100 inside the
    edges), or a weave of :data:`AMPLITUDES` at :data:`MARGIN` of its two-pass spacing and of its reach,
    among those whose one pass reaches at least as far as the law's straight pass (d100, the outer ring and
    the centre rely on one pass; both as flown here, :func:`pass_profile`), its
    outer ring half its reach inside the edges (a corner of the domain is then within reach of the ring's
    corner). The spiral's time is its length over the sweep's forward speed: on a square the rings come in
    whole numbers, and of weaves that fit the same rings the narrower, faster one is sooner (the paper's
    square: A = 0.45 and 0.5 both give rings 11.2 apart, spirals of 1,027 and 1,029 units at 0.900 and
    0.878 k_v). The processes that plan and those that fly each compute it from the scenario they agreed on
    (:mod:`protocol.agreement`); it is deterministic, the same numba kernels on the same inputs. A scenario with
    ``weave = false`` sweeps straight. Cached: every flight the planner foresees asks for it (through
    :func:`model.controllers.anicov.law.anicov_law`), and the straight pass's spacing and reach are integrals."""
    if not scenario.weave:
        return _straight(best_lane_spacing(scenario), pass_reach(scenario), scenario.k_v)
    return _sweep_of(tuple(scenario.domain), PassLaw.of(scenario), best_lane_spacing(scenario), pass_reach(scenario))


@functools.lru_cache(maxsize=16)
def _sweep_of(domain: tuple[float, float], law: PassLaw, straight_spacing: float, straight_reach: float) -> Sweep:
    """:func:`sweep_of` of a domain, sensor and robot (cached: every weave's pass is flown once per sensor)."""
    wavelength = WAVELENGTH_PER_RANGE * law.sensing_range
    best = _straight(straight_spacing, straight_reach, law.k_v)
    soonest = _spiral_time(domain, best)
    bar = one_pass_reach(*pass_profile(0.0, wavelength, law)[:2])  # d100 as the law flies it (2.69 for 2.72)
    for amplitude in AMPLITUDES:
        offsets, profile, forward = pass_profile(amplitude, wavelength, law)
        reach = one_pass_reach(offsets, profile)
        if reach < bar:
            continue
        weave = Sweep(
            amplitude, wavelength, MARGIN * two_pass_spacing(offsets, profile), MARGIN * reach, reach / 2.0,
            forward, WEAVE_CENTRE_LEADS,
        )  # fmt: skip
        time = _spiral_time(domain, weave)
        if time < soonest:
            best, soonest = weave, time
    return best


def _spiral_time(domain: tuple[float, float], sweep: Sweep) -> float:
    """How long the sweep's one-robot spiral of ``domain`` takes at its forward speed."""
    whole = Route.of(spiral_in(domain[0], domain[1], sweep.reach, sweep.spacing, sweep.edge))
    return whole.length / sweep.forward


def _straight(spacing: float, reach: float, k_v: float) -> Sweep:
    """Straight passes (no weave) at ``spacing``, reaching ``reach``, the outer ring that far inside."""
    return Sweep(0.0, 1.0, spacing, reach, reach, k_v)


def pass_profile(amplitude: float, wavelength: float, law: PassLaw) -> tuple[np.ndarray, np.ndarray, float]:
    """(offsets across the course, Λ/Λ* there at the least-covered phase, forward speed) of one pass along
    a straight course, flown as the engine flies a route: from the course's start heading along it, a carrot
    :data:`LOOKAHEAD` ahead of the robot's progress every ``plan_steps`` steps, :func:`model.paper.control.
    pursuit_law` with the weave, eq. 1 exactly; the wedge's ability (eq. 2) summed over the steps (eq. 3)
    at points across the course, over one wavelength far enough along that the start is behind them."""
    start = law.sensing_range + 4.0 * wavelength  # the weave has settled, the run-up is behind
    course = start + wavelength + law.sensing_range + LOOKAHEAD + 1.0
    xs, ys, thetas = flown_course(amplitude, wavelength, law, course)
    across = 2.0 * law.sensing_range * math.sin(law.half_angle) + 2.0  # two passes reach no farther apart
    offsets = np.arange(-across, across + 1e-9, OFFSET_STEP)
    along = start + wavelength * np.arange(PHASES) / PHASES
    points_x = np.repeat(along[None, :], len(offsets), axis=0).ravel()
    points_y = np.repeat(offsets[:, None], PHASES, axis=1).ravel()
    sensed = _coverage(xs, ys, thetas, points_x, points_y, law.sensing_range, law.half_angle, law.alpha_max, law.dt)
    profile = sensed.reshape(len(offsets), PHASES).min(axis=1) / law.lambda_star
    forward = float((xs[-1] - xs[0]) / (law.dt * (len(xs) - 1)))
    return offsets, profile, forward


def flown_course(
    amplitude: float, wavelength: float, law: PassLaw, course: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The poses, one per step, of a robot flying the x axis from the origin to ``course`` (at most
    :data:`COURSE_STEPS_PER_UNIT` steps a unit: a law that does not get there gives a profile that reaches
    nothing, and its amplitude is not taken)."""
    x = y = theta = progress = 0.0
    poses = []
    step = 0
    while x < course and step < COURSE_STEPS_PER_UNIT * course:
        if step % law.plan_steps == 0:
            progress = max(progress, min(max(x, 0.0), progress + LOOKAHEAD))
        poses.append((x, y, theta))
        v, omega = pursuit_law(
            x, y, theta, progress + LOOKAHEAD, 0.0, law.k_v, law.k_omega, law.dt, amplitude, wavelength
        )
        x, y, theta = unicycle_step(x, y, theta, v, omega, law.dt)
        step += 1
    flown = np.array(poses)
    return flown[:, 0], flown[:, 1], flown[:, 2]


@njit(cache=True)
def _coverage(
    xs: np.ndarray,
    ys: np.ndarray,
    thetas: np.ndarray,
    points_x: np.ndarray,
    points_y: np.ndarray,
    sensing_range: float,
    half_angle: float,
    alpha_max: float,
    dt: float,
) -> np.ndarray:
    """Λ at each point after the poses, eq. 3 with the ability of eq. 2 (as :mod:`model.paper.sensing` tests the
    wedge)."""
    sensed = np.zeros(len(points_x))
    cos_half = math.cos(half_angle)
    for k in range(len(xs)):
        heading_x, heading_y = math.cos(thetas[k]), math.sin(thetas[k])
        for p in range(len(points_x)):
            distance, along, across = wedge_reach(
                points_x[p] - xs[k], points_y[p] - ys[k], heading_x, heading_y, sensing_range, cos_half
            )
            if distance < 0.0:
                continue
            offset = offset_from_heading(distance, along, across)
            sensed[p] += sensing_ability(distance, offset, sensing_range, half_angle, alpha_max) * dt
    return sensed


def one_pass_reach(offsets: np.ndarray, profile: np.ndarray) -> float:
    """How far to either side of its course one pass brings Λ* (the least of the two sides)."""
    covered = profile >= 1.0
    centre = int(np.argmin(np.abs(offsets)))
    if not covered[centre]:
        return 0.0
    right = centre
    while right + 1 < len(offsets) and covered[right + 1]:
        right += 1
    left = centre
    while left > 0 and covered[left - 1]:
        left -= 1
    return float(min(offsets[right], -offsets[left]))


def two_pass_spacing(offsets: np.ndarray, profile: np.ndarray) -> float:
    """The widest spacing at which two passes the same way bring every point between them to Λ*
    (:data:`OFFSET_STEP` apart; 0 if none)."""
    step = float(offsets[1] - offsets[0])
    centre = int(np.argmin(np.abs(offsets)))
    widest = 0.0
    for shift in range(1, min(centre, len(offsets) - 1 - centre) + 1):
        between = np.arange(centre, centre + shift + 1)  # the points from one course to the other
        if (profile[between] + profile[between - shift]).min() >= 1.0:
            widest = shift * step
        elif widest > 0.0:
            break
    return widest
