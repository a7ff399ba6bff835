"""The safety filter (issue 12): between the coverage law and the robot, the command nearest the law's
that keeps robots apart and off the walls, from one robot's own view. Rules in docs/safety.md.

Formulation: barrier certificates on a look-ahead point, as the Robotarium's
(Wang, Ames & Egerstedt, "Safety barrier certificates for collisions-free multirobot systems", IEEE
T-RO 33(3), 2017; Robotarium rps ``create_uni_barrier_certificate``), in the discrete-time form of
Agrawal & Sreenath (RSS 2017), with each robot taking half of each pair's constraint (decentralised).

* The point p = c + l·(cos θ, sin θ) ahead of the centre c moves as a single integrator:
  ṗ = u = v·e + l·ω·e⊥, so z = (v, l·ω) is u in the robot's frame and |u − û| = |z − ẑ|.
* Over one step with (v, ω) held, p moves by Δ = dt·sinc(ω·dt/2)·R(ω·dt/2)·u; |Δ − u·dt| ≤ ε with
  ε = u_max·ω_max·dt²/2 (the slack).
* Robot pair: h = |p_i − p_j| − D, D = 2r + s + 2l (+ how far a teammate's point may have moved since
  its pose was sent). With n = (p_i − p_j)/|p_i − p_j|, |p'_i − p'_j| ≥ n·(p'_i − p'_j), so if each robot
  keeps n·Δ_i ≥ −½·γ·h, then h_{k+1} ≥ (1 − γ)·h_k ≥ 0: the points stay D apart, the centres 2r + s.
  Each robot imposes n·u ≥ (−½·γ·h + ε)/dt on itself.
* Wall cell (a closed square) or map edge: q its point nearest the centre c, n = (c − q)/|c − q|: the whole
  cell lies behind the line through q normal to n, so h = n·(c − q) − (r + s) ≥ 0 keeps the disk s off it.
  A wall does not move, so the centre itself carries this barrier, with the whole of γ:
  v·dt·(n·e) − |v|·dt·κ ≥ −γ·h, κ = ω_max·dt/2 (the arc's turn off its chord), two half-planes in v.
* Velocity bounds of the paper: |v| ≤ k_v, |ω| ≤ π·k_ω (eq. 15–16), as four more half-planes.
* The QP min |z − ẑ|² over them is solved exactly (:mod:`model.barrier_qp`); if it is empty the robot
  stops (v = ω = 0: Δ = 0 keeps its half of every constraint), as the Robotarium's does.

Deadlock (a robot held still by a teammate for ``STUCK_STEPS`` steps): the standard remedy of a
rotation bias (the "keep right" rule, Wang et al. 2017, Sec. VI; Grover et al. 2016): the nominal
velocity is turned by ``KEEP_RIGHT`` to the robot's right until the law's own command passes the filter
again (resolved) or ``DETOUR_STEPS`` have gone (given up; it may be found again). A rotation of a velocity
near zero does nothing, and a robot held while it *turns in place* (its law asks the look-ahead point to
move mostly by turning: |v̂| < l·|ω̂|, as near an objective, where eq. 10 stops it and turns it to look)
asks for just that: two robots side by side turning toward the same blob swing their points at each
other and stay frozen. There the priority rule settles it: the robot whose nearest teammate has the
lower id yields, driving its point straight away from that teammate's at k_v for ``YIELD_STEPS`` steps,
so the other can turn (the id order of Alg. 2's own tie-breaking; priority-based yielding as in
Čáp, Novák, Kleiner & Selecký, IEEE T-ASE 12(3), 2015).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from model.barrier_qp import project_onto_polygon
from model.geometry import wrap_angle
from model.ground import Ground

FILTER_CHANGED = 1  # the command differs from the law's
KEEPING_RIGHT = 2  # a deadlock's detour is under way (keeping right or yielding)
NO_SAFE_COMMAND = 4  # the QP was empty: stopped
STALE_NEIGHBOUR = 8  # a teammate in range sent no pose for max_pose_age: stopped
DEADLOCK_FOUND = 16  # held by a teammate for STUCK_STEPS: the detour starts
DEADLOCK_RESOLVED = 32  # the law's command passes again after a detour
RAN_LATE = 64  # realtime: the control loop fell behind its clock; the robot held still for this step
POSE_STALE = 128  # a real base sent no pose for its timeout: held still, nothing sensed (agents.ros2)

STUCK_STEPS = 10
"""Steps a robot may be held by a teammate (moving at under HELD_FRACTION of the law's speed) before
it is called a deadlock."""
HELD_FRACTION = 0.25
WANTS_TO_MOVE = 0.05
"""A robot held is one whose law asks for more than this fraction of k_v."""
KEEP_RIGHT = math.radians(60.0)
DETOUR_STEPS = 100
"""The most steps one detour lasts before it is given up."""
YIELD_STEPS = 20
"""Steps a robot yielding to a lower-id teammate drives away from it (2 time units at dt = 0.1)."""

HELD, DETOUR, YIELDING = 0, 1, 2
MEMORY_SIZE = 3
"""A robot's deadlock state (``memory``): steps held so far, steps of the detour under way, and whether
that detour is a yield (1) or keeping right (0)."""

TEAMMATE, PARKED = 0, 1
"""How a teammate takes part: it filters too (half of each constraint each), or it no longer moves
(its process died: the whole constraint is this robot's)."""


class SafetyParameters(NamedTuple):
    """The filter's constants, from the scenario (:func:`model.parameters.safety_parameters`)."""

    enabled: bool
    radius: float  # r
    margin: float  # s
    lookahead: float  # l
    decay: float  # γ = min(1, barrier_gain·dt): h_{k+1} ≥ (1 − γ)·h_k
    reach: float  # safety_range: teammates farther (centre to centre) are left out
    v_max: float  # k_v
    omega_max: float  # π·k_ω
    dt: float
    point_speed: float  # u_max = sqrt(k_v² + (l·ω_max)²): the fastest a look-ahead point moves
    slack: float  # ε = u_max·ω_max·dt²/2
    max_pose_age: float  # a teammate's pose older than this, in range: stop


def disabled_safety() -> SafetyParameters:
    """No filter: the paper's robots (and any run with point robots or ``safety = false``)."""
    return SafetyParameters(False, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, math.inf)


@njit(cache=True)
def _add(gx, gy, c, count, nx, ny, theta, bound):
    """The half-plane n·u ≥ bound, written in z: n·u = z_v·(n·e) + z_l·(n·e⊥)."""
    cos_t, sin_t = math.cos(theta), math.sin(theta)
    gx[count] = nx * cos_t + ny * sin_t
    gy[count] = -nx * sin_t + ny * cos_t
    c[count] = bound
    return count + 1


@njit(cache=True)
def _pair_bound(distance: float, clearance: float, share: float, safety: SafetyParameters) -> float:
    """The least n·u for a barrier h = distance − clearance, this robot taking ``share`` of it."""
    return (-share * safety.decay * (distance - clearance) + safety.slack) / safety.dt


@njit(cache=True)
def _teammates(gx, gy, c, count, px, py, theta, me, poses, ages, kinds, safety):
    """Constraints from the teammates within reach; (count, any live teammate too old, count before)."""
    ahead = safety.lookahead
    stale = False
    for j in range(poses.shape[0]):
        if j == me or not math.isfinite(poses[j, 0]):
            continue
        spread = safety.point_speed * ages[j]  # where its point may be by now
        centre_distance = math.hypot(poses[me, 0] - poses[j, 0], poses[me, 1] - poses[j, 1])
        if centre_distance - spread > safety.reach:
            continue
        if kinds[j] == TEAMMATE and ages[j] > safety.max_pose_age:
            stale = True
        qx, qy = poses[j, 0] + ahead * math.cos(poses[j, 2]), poses[j, 1] + ahead * math.sin(poses[j, 2])
        dx, dy = px - qx, py - qy
        distance = math.hypot(dx, dy)
        if distance > 0.0:
            nx, ny = dx / distance, dy / distance
        else:  # one point on the other: back off
            nx, ny = -math.cos(theta), -math.sin(theta)
        clearance = 2.0 * safety.radius + safety.margin + 2.0 * ahead + spread
        share = 0.5 if kinds[j] == TEAMMATE else 1.0
        count = _add(gx, gy, c, count, nx, ny, theta, _pair_bound(distance, clearance, share, safety))
    return count, stale


@njit(cache=True)
def _wall(gx, gy, c, normals, count, nx, ny, distance, theta, safety):
    """The centre's barrier against one wall point: h = n·(c − q) − (r + s), kept by
    n·Δc ≥ v·dt·(n·e) − |v|·dt·κ ≥ −γ·h (κ = ω_max·dt/2 bounds the arc's turn off the chord), written as
    two half-planes in v (one for each sign of v), both held by v = 0 while h ≥ 0."""
    kappa = 0.5 * safety.omega_max * safety.dt
    along = nx * math.cos(theta) + ny * math.sin(theta)
    bound = -safety.decay * (distance - safety.radius - safety.margin) / safety.dt
    for sign in (-1.0, 1.0):
        gx[count], gy[count], c[count] = along + sign * kappa, 0.0, bound
        normals[count, 0], normals[count, 1] = nx, ny
        count += 1
    return count


@njit(cache=True)
def _walls(gx, gy, c, normals, count, x, y, theta, occupied, cell, bounded, safety):
    """Constraints from the occupied cells (and, on a map, its edges) one step could bring within reach.

    Walls do not move, so their barrier is on the centre itself (exact, and tight: a barrier on the
    look-ahead point would keep a robot facing a wall up to 2l farther off it than s). Only v appears
    in it; the law's ω turns the robot away."""
    band = safety.radius + safety.margin + 2.0 * safety.v_max * safety.dt  # farther cannot be reached this step
    rows, cols = occupied.shape
    if bounded:
        for nx, ny, distance in (
            (1.0, 0.0, x),
            (0.0, 1.0, y),
            (-1.0, 0.0, cols * cell - x),
            (0.0, -1.0, rows * cell - y),
        ):
            if distance <= band:
                count = _wall(gx, gy, c, normals, count, nx, ny, distance, theta, safety)
    col0, col1 = max(math.floor((x - band) / cell), 0), min(math.floor((x + band) / cell), cols - 1)
    row0, row1 = max(math.floor((y - band) / cell), 0), min(math.floor((y + band) / cell), rows - 1)
    for row in range(row0, row1 + 1):
        for col in range(col0, col1 + 1):
            if not occupied[row, col]:
                continue
            qx = min(max(x, col * cell), (col + 1) * cell)  # the square's point nearest the centre
            qy = min(max(y, row * cell), (row + 1) * cell)
            distance = math.hypot(x - qx, y - qy)
            if distance > band:
                continue
            if distance > 0.0:
                count = _wall(
                    gx, gy, c, normals, count, (x - qx) / distance, (y - qy) / distance, distance, theta, safety
                )
            else:  # inside a wall (a pose given so): no direction out is known, stay
                count = _wall(gx, gy, c, normals, count, math.cos(theta), math.sin(theta), 0.0, theta, safety)
    return count


@njit(cache=True)
def safe_velocities(
    v_hat: float,
    omega_hat: float,
    me: int,
    poses: np.ndarray,
    ages: np.ndarray,
    kinds: np.ndarray,
    ground: Ground,
    cell: float,
    safety: SafetyParameters,
    turn: float,
) -> tuple[float, float, bool, bool, bool, float, float]:
    """The QP for robot ``me`` at ``poses[me]``: the safe (v, ω) nearest the law's (v̂, ω̂), whose
    velocity is first turned by ``turn`` (a detour). Returns (v, ω, feasible, a teammate binds the law's
    command, a live teammate in reach is older than max_pose_age, the normal of the wall it presses on
    most or (0, 0))."""
    x, y, theta = poses[me, 0], poses[me, 1], poses[me, 2]
    ahead = safety.lookahead
    px, py = x + ahead * math.cos(theta), y + ahead * math.sin(theta)
    window = math.ceil(2.0 * (safety.radius + safety.margin + 2.0 * safety.v_max * safety.dt) / cell) + 2
    capacity = 8 + poses.shape[0] + 2 * window * window
    gx, gy, c = np.zeros(capacity), np.zeros(capacity), np.zeros(capacity)
    # The paper's bounds |v| ≤ k_v, |ω| ≤ π·k_ω, in z = (v, l·ω).
    gx[0], gx[1], gy[2], gy[3] = 1.0, -1.0, 1.0, -1.0
    c[0] = c[1] = -safety.v_max
    c[2] = c[3] = -ahead * safety.omega_max
    first_teammate = count = 4
    count, stale = _teammates(gx, gy, c, count, px, py, theta, me, poses, ages, kinds, safety)
    binding = False
    for k in range(first_teammate, count):
        binding = binding or gx[k] * v_hat + gy[k] * ahead * omega_hat < c[k]
    normals = np.zeros((capacity, 2))
    first_wall = count
    count = _walls(gx, gy, c, normals, count, x, y, theta, ground.occupied, cell, ground.bounded, safety)
    target_v = math.cos(turn) * v_hat - math.sin(turn) * ahead * omega_hat
    target_l = math.sin(turn) * v_hat + math.cos(turn) * ahead * omega_hat
    feasible, v, lw = project_onto_polygon(gx, gy, c, count, target_v, target_l)
    worst, wall_x, wall_y = 0.0, 0.0, 0.0  # the wall the law's command presses on most
    for k in range(first_wall, count):
        shortfall = c[k] - (gx[k] * target_v + gy[k] * target_l)
        if shortfall > worst:
            worst, wall_x, wall_y = shortfall, normals[k, 0], normals[k, 1]
    return v, lw / ahead, feasible, binding, stale, wall_x, wall_y


@njit(cache=True)
def filter_command(
    v_hat: float,
    omega_hat: float,
    me: int,
    poses: np.ndarray,
    ages: np.ndarray,
    kinds: np.ndarray,
    ground: Ground,
    cell: float,
    safety: SafetyParameters,
    memory: np.ndarray,
) -> tuple[float, float, int]:
    """The command robot ``me`` applies, and what the filter did (the flag bits above).

    ``poses`` (N, 3): every robot's last known pose, this one's current; ``ages`` (N,): how old each is
    (0 in lockstep); ``kinds``: TEAMMATE or PARKED; ``memory`` (MEMORY_SIZE,): the deadlock state, updated
    in place (the engine and the agent both keep it, so lockstep agrees)."""
    v, omega, feasible, binding, stale, wall_x, wall_y = safe_velocities(
        v_hat, omega_hat, me, poses, ages, kinds, ground, cell, safety, 0.0
    )
    if stale:  # it depends on the poses alone, not on the command
        memory[HELD] = 0
        return 0.0, 0.0, STALE_NEIGHBOUR
    law_omega = omega_hat  # what FILTER_CHANGED compares with, also when the slide turns the nominal
    pressed = wall_x != 0.0 or wall_y != 0.0
    if not binding and pressed and abs(v_hat) > 0.01 * safety.v_max and abs(v) < HELD_FRACTION * abs(v_hat):
        # Pressed on a wall (the law drives into it and the wall stops it): slide along it (see _slide).
        omega_hat = _slide(poses[me, 2], wall_x, wall_y, safety)
        v, omega, feasible, binding, _, _, _ = safe_velocities(
            v_hat, omega_hat, me, poses, ages, kinds, ground, cell, safety, 0.0
        )
    flags = 0
    if memory[DETOUR] > 0 and memory[YIELDING] == 1:  # yielding: away from the teammate, YIELD_STEPS in all
        away_x, away_y = _yield_direction(me, poses, safety)
        if memory[DETOUR] >= YIELD_STEPS or (away_x == 0.0 and away_y == 0.0):
            memory[DETOUR] = memory[YIELDING] = 0
            if feasible and not _held(v_hat, omega_hat, v, omega, binding, safety):
                flags |= DEADLOCK_RESOLVED
        else:
            memory[DETOUR] += 1
            flags |= KEEPING_RIGHT
            v, omega, feasible = _drive_along(away_x, away_y, me, poses, ages, kinds, ground, cell, safety)
    elif memory[DETOUR] > 0:  # keeping right: back on the law's command once it passes the filter
        if feasible and not _held(v_hat, omega_hat, v, omega, binding, safety):
            memory[DETOUR] = 0
            flags |= DEADLOCK_RESOLVED
        elif memory[DETOUR] >= DETOUR_STEPS:
            memory[DETOUR] = 0
        else:
            memory[DETOUR] += 1
            flags |= KEEPING_RIGHT
            v, omega, feasible, _, _, _, _ = safe_velocities(
                v_hat, omega_hat, me, poses, ages, kinds, ground, cell, safety, -KEEP_RIGHT
            )
    elif binding and _held(v_hat, omega_hat, v if feasible else 0.0, omega if feasible else 0.0, binding, safety):
        memory[HELD] += 1
        if memory[HELD] >= STUCK_STEPS:
            memory[HELD] = 0
            memory[DETOUR] = 1
            flags |= DEADLOCK_FOUND
            turning = abs(v_hat) < safety.lookahead * abs(omega_hat)
            away_x, away_y = _yield_direction(me, poses, safety)
            if turning and (away_x != 0.0 or away_y != 0.0):
                memory[YIELDING] = 1
                flags |= KEEPING_RIGHT
                v, omega, feasible = _drive_along(away_x, away_y, me, poses, ages, kinds, ground, cell, safety)
    else:
        memory[HELD] = 0
    if not feasible:
        return 0.0, 0.0, flags | NO_SAFE_COMMAND
    if abs(v - v_hat) + safety.lookahead * abs(omega - law_omega) > 1e-12 * (1.0 + abs(v_hat)):
        flags |= FILTER_CHANGED
    return v, omega, flags


@njit(cache=True)
def _yield_direction(me: int, poses: np.ndarray, safety: SafetyParameters) -> tuple[float, float]:
    """The unit vector from the nearest teammate's look-ahead point (within safety_range, centre to centre)
    to this robot's, when that teammate has the lower id (this robot yields); else (0, 0)."""
    ahead = safety.lookahead
    x, y, theta = poses[me, 0], poses[me, 1], poses[me, 2]
    px, py = x + ahead * math.cos(theta), y + ahead * math.sin(theta)
    nearest, best, away_x, away_y = -1, math.inf, 0.0, 0.0
    for j in range(poses.shape[0]):
        if j == me or not math.isfinite(poses[j, 0]):
            continue
        if math.hypot(x - poses[j, 0], y - poses[j, 1]) > safety.reach:
            continue
        dx = px - poses[j, 0] - ahead * math.cos(poses[j, 2])
        dy = py - poses[j, 1] - ahead * math.sin(poses[j, 2])
        distance = math.hypot(dx, dy)
        if distance < best:
            nearest, best = j, distance
            away_x, away_y = (dx / distance, dy / distance) if distance > 0.0 else (-math.cos(theta), -math.sin(theta))
    if nearest < 0 or nearest > me:
        return 0.0, 0.0
    return away_x, away_y


@njit(cache=True)
def _drive_along(
    away_x: float,
    away_y: float,
    me: int,
    poses: np.ndarray,
    ages: np.ndarray,
    kinds: np.ndarray,
    ground: Ground,
    cell: float,
    safety: SafetyParameters,
) -> tuple[float, float, bool]:
    """The safe command nearest moving the look-ahead point along (away_x, away_y) at k_v: the nominal
    z = k_v·(n·e, n·e⊥) in the robot's frame, through the same QP."""
    theta = poses[me, 2]
    cos_t, sin_t = math.cos(theta), math.sin(theta)
    v_hat = safety.v_max * (away_x * cos_t + away_y * sin_t)
    omega_hat = safety.v_max * (-away_x * sin_t + away_y * cos_t) / safety.lookahead
    v, omega, feasible, _, _, _, _ = safe_velocities(
        v_hat, omega_hat, me, poses, ages, kinds, ground, cell, safety, 0.0
    )
    return v, omega, feasible


SLIDE_AWAY = math.radians(20.0)
"""How far from the wall's tangent a robot sliding along it heads: at the barrier (h = 0) the filter lets a
robot move only if it heads away from the wall by more than asin(κ) (9° at the paper's gains)."""


@njit(cache=True)
def _slide(theta: float, wall_x: float, wall_y: float, safety: SafetyParameters) -> float:
    """An ω that slides a robot pressed on a wall along it (the wall-following rule of bug algorithms):
    toward the wall's tangent nearest its heading, SLIDE_AWAY off the wall; head-on, to the right. The
    centre barrier holds v alone, so a robot heading into a wall whose law does not turn it would stand
    there for ever. From the heading, not the law's wish: that one may point back into the wall."""
    gain = safety.omega_max / math.pi  # k_ω
    along = math.cos(theta) * wall_x + math.sin(theta) * wall_y
    tx, ty = math.cos(theta) - along * wall_x, math.sin(theta) - along * wall_y
    if math.hypot(tx, ty) < 1e-6:
        tx, ty = -wall_y, wall_x  # straight at it: to the right (n points back at the robot)
    side = math.atan2(ty, tx)
    heading = side + SLIDE_AWAY * math.sin(wrap_angle(math.atan2(wall_y, wall_x) - side))
    return gain * wrap_angle(heading - theta)


@njit(cache=True)
def _held(v_hat: float, omega_hat: float, v: float, omega: float, binding: bool, safety: SafetyParameters) -> bool:
    """A teammate's constraint binds and the robot moves at under HELD_FRACTION of what its law asks."""
    ahead = safety.lookahead
    asked = math.hypot(v_hat, ahead * omega_hat)
    return binding and asked > WANTS_TO_MOVE * safety.v_max and math.hypot(v, ahead * omega) < HELD_FRACTION * asked


def load_kernels(safety: SafetyParameters, ground: Ground, cell: float, agents: int) -> None:
    """Have numba load the filter now, with the real argument types, on scratch state (see
    model.step.load_kernels)."""
    if not safety.enabled:
        return
    poses = np.zeros((agents, 3))
    poses[:, 0] = np.arange(agents) * 1e3  # nobody near anybody
    filter_command(
        0.0,
        0.0,
        0,
        poses,
        np.zeros(agents),
        np.zeros(agents, dtype=np.int64),
        ground,
        cell,
        safety,
        np.zeros(MEMORY_SIZE, dtype=np.int64),
    )
