"""The safety filter's constraints and its QP (issue 12): barrier certificates on a look-ahead point for
each teammate within reach, the centre's barrier for each wall cell and map edge, the paper's velocity
bounds, and the safe (v, ω) nearest a nominal one (:func:`safe_velocities`). The formulation, with its
citations, is in :mod:`model.safety.safety`, which decides what to ask of it (deadlocks, walls)."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from model.safety.barrier_qp import project_onto_polygon
from model.world.ground import Ground

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
    pair_margin: float  # s between two robots: s and each one's clearance reserve (model.scenario.physics_keys)


def disabled_safety() -> SafetyParameters:
    """No filter: the paper's robots (and any run with point robots or ``safety = false``)."""
    return SafetyParameters(False, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, math.inf, 0.0)


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
        clearance = 2.0 * safety.radius + safety.pair_margin + 2.0 * ahead + spread
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
    window = math.ceil(2.0 * (safety.radius + safety.margin + 2.0 * safety.v_max * safety.dt) / ground.grain) + 2
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
    count = _walls(gx, gy, c, normals, count, x, y, theta, ground.wall_grid, ground.grain, ground.bounded, safety)
    target_v = math.cos(turn) * v_hat - math.sin(turn) * ahead * omega_hat
    target_l = math.sin(turn) * v_hat + math.cos(turn) * ahead * omega_hat
    feasible, v, lw = project_onto_polygon(gx, gy, c, count, target_v, target_l)
    if not feasible:
        # A centre already inside a wall's margin (h < 0: a belief off the truth, a late command) is asked to
        # get out at γ·|h| per step. Nearly along the wall (|n·e| < κ) no v does that, and the robot stood
        # for good, v = ω = 0 (two rooms, the noise: 1.05 from its station at a wall's end, for the
        # rest of the run). Asked only not to go deeper, it may stand and turn; its next step can then leave.
        _only_not_deeper(c, first_wall, count, 0.0)
        feasible, v, lw = project_onto_polygon(gx, gy, c, count, target_v, target_l)
    if not feasible:
        # The same inside a teammate's margin (h < 0: its bound is above the slack's ε/dt): a point that must leave
        # sideways at γ·|h| per step cannot (a unicycle's point moves sideways at most l·ω_max), and two robots
        # stood for good, v = ω = 0 (a corridor, commands 1.0 late, the teammate ahead and a wall's margin
        # behind). Asked only not to come nearer, the one may back off and the other turn. A barrier that still
        # holds (h ≥ 0) keeps its bound, slack and all; if the QP is still empty the robot stops.
        _only_not_deeper(c, first_teammate, first_wall, safety.slack / safety.dt)
        feasible, v, lw = project_onto_polygon(gx, gy, c, count, target_v, target_l)
    worst, wall_x, wall_y = 0.0, 0.0, 0.0  # the wall the law's command presses on most
    for k in range(first_wall, count):
        shortfall = c[k] - (gx[k] * target_v + gy[k] * target_l)
        if shortfall > worst:
            worst, wall_x, wall_y = shortfall, normals[k, 0], normals[k, 1]
    return v, lw / ahead, feasible, binding, stale, wall_x, wall_y


@njit(cache=True)
def _only_not_deeper(c: np.ndarray, first: int, last: int, inside: float) -> None:
    """Barriers ``first`` to ``last`` whose bound is above ``inside`` (the robot is inside their margin: h < 0)
    ask only that it go no deeper: bound 0."""
    for k in range(first, last):
        if c[k] > inside:
            c[k] = 0.0
