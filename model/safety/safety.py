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
* The QP min |z − ẑ|² over them is solved exactly (:mod:`model.safety.barrier_qp`). If it is empty, the
  barriers already broken (h < 0: a belief off the truth, a late command), walls first and then teammates, ask
  only not to go deeper; if it is empty still the robot stops (v = ω = 0: Δ = 0 keeps its half of every
  constraint), as the Robotarium's does. Where every barrier holds, nothing is relaxed.

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

import numpy as np
from numba import njit

from model.safety.barrier_constraints import PARKED, TEAMMATE, SafetyParameters, disabled_safety, safe_velocities
from model.safety.wall_slide import slide_along_wall
from model.world.ground import Ground

__all__ = ["PARKED", "TEAMMATE", "SafetyParameters", "disabled_safety", "filter_command", "safe_velocities"]

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

RELAPSE_STEPS = 3 * STUCK_STEPS
"""A deadlock found again within this many steps of a detour that kept right and "resolved" it was not
resolved: the robot yields, whatever the ids (:func:`_deadlock`)."""

HELD, DETOUR, YIELDING, TURNING, TURNING_OUT, RELAPSE = 0, 1, 2, 3, 4, 5
MEMORY_SIZE = 6
"""A robot's deadlock state (``memory``): steps held so far, steps of the detour under way, whether
that detour is a yield to a lower id (1), a yield whatever the ids (2) or keeping right (0), the way
(+1 left, −1 right, 0 none) of a turn in place taken the long way round (:func:`_other_way`), whether
that turn is a deadlock's way out (1), and the steps left in which a deadlock found again is a relapse."""


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
        memory[HELD] = memory[TURNING] = memory[TURNING_OUT] = 0
        return 0.0, 0.0, STALE_NEIGHBOUR
    law_omega = omega_hat  # what FILTER_CHANGED compares with, also when the slide turns the nominal
    memory[RELAPSE] = max(memory[RELAPSE] - 1, 0)
    pressed = wall_x != 0.0 or wall_y != 0.0
    if not binding and pressed and abs(v_hat) > 0.01 * safety.v_max and abs(v) < HELD_FRACTION * abs(v_hat):
        # Pressed on a wall (the law drives into it and the wall stops it): slide along it (model.safety.wall_slide), in
        # the direction the law drives: a robot reversing into a wall turned by the forward slide until it
        # faced away from the wall, its back still on it, and stood there for good (issue 34's lab map).
        travel = poses[me, 2] if v_hat >= 0.0 else poses[me, 2] + math.pi
        omega_hat = slide_along_wall(travel, wall_x, wall_y, safety)
        v, omega, feasible, binding, _, _, _ = safe_velocities(
            v_hat, omega_hat, me, poses, ages, kinds, ground, cell, safety, 0.0
        )
    flags = 0
    if memory[DETOUR] == 0:
        v, omega, feasible, omega_hat, flags = _other_way(
            v_hat, omega_hat, v, omega, feasible, binding, me, poses, ages, kinds, ground, cell, safety, memory
        )
    if memory[DETOUR] > 0:  # a detour under way: yielding or keeping right
        passes = feasible and not _held(v_hat, omega_hat, v, omega, binding, safety)
        v, omega, feasible, flags = _detour(
            v_hat, omega_hat, v, omega, feasible, passes, me, poses, ages, kinds, ground, cell, safety, memory
        )
    elif binding and _held(v_hat, omega_hat, v if feasible else 0.0, omega if feasible else 0.0, binding, safety):
        memory[HELD] += 1
        if memory[HELD] >= STUCK_STEPS:
            v, omega, feasible, found = _deadlock(
                v_hat, omega_hat, v, omega, feasible, me, poses, ages, kinds, ground, cell, safety, memory
            )
            flags |= found
    else:
        memory[HELD] = 0
    if not feasible:
        return 0.0, 0.0, flags | NO_SAFE_COMMAND
    if abs(v - v_hat) + safety.lookahead * abs(omega - law_omega) > 1e-12 * (1.0 + abs(v_hat)):
        flags |= FILTER_CHANGED
    return v, omega, flags


@njit(cache=True)
def _deadlock(
    v_hat: float,
    omega_hat: float,
    v: float,
    omega: float,
    feasible: bool,
    me: int,
    poses: np.ndarray,
    ages: np.ndarray,
    kinds: np.ndarray,
    ground: Ground,
    cell: float,
    safety: SafetyParameters,
    memory: np.ndarray,
) -> tuple[float, float, bool, int]:
    """A deadlock found (held STUCK_STEPS): its first step, (v, ω, feasible, flags). A robot turning in place
    yields when its nearest teammate has the lower id; else, its teammate being the one to give way and this
    one still held, it turns the long way round if that way is free (:func:`_other_way`); anything else
    keeps right (a detour).

    A deadlock found again within RELAPSE_STEPS of keeping right "resolved" one is a relapse: the robot
    yields, whatever the ids. Its teammate may be the one that cannot give way: turning in place with a
    wall ahead, where each turn toward its goal swings its look-ahead point at this robot's, so that the
    law's command passes here for a step or two and is held again, for good (issue 34, the lab map at
    N = 8: two robots stood so for the rest of the run, a cell left unseen behind them)."""
    memory[HELD] = 0
    memory[DETOUR] = 1
    flags = DEADLOCK_FOUND
    turning = abs(v_hat) < safety.lookahead * abs(omega_hat)
    relapse = memory[RELAPSE] > 0
    away_x, away_y = _yield_direction(me, poses, safety, relapse)
    if (turning or relapse) and (away_x != 0.0 or away_y != 0.0):
        memory[YIELDING] = 2 if relapse else 1
        v, omega, feasible = _drive_along(away_x, away_y, me, poses, ages, kinds, ground, cell, safety)
        return v, omega, feasible, flags | KEEPING_RIGHT
    if _in_place(v_hat, omega_hat, safety):
        v_other, omega_other, feasible_other, turns = _long_way(
            v_hat, omega_hat, me, poses, ages, kinds, ground, cell, safety, memory
        )
        if turns:
            memory[DETOUR], memory[TURNING_OUT] = 0, 1
            return v_other, omega_other, feasible_other, flags
    return v, omega, feasible, flags


@njit(cache=True)
def _other_way(
    v_hat: float,
    omega_hat: float,
    v: float,
    omega: float,
    feasible: bool,
    binding: bool,
    me: int,
    poses: np.ndarray,
    ages: np.ndarray,
    kinds: np.ndarray,
    ground: Ground,
    cell: float,
    safety: SafetyParameters,
    memory: np.ndarray,
) -> tuple[float, float, bool, float, int]:
    """A turn in place the filter holds, taken the long way round: (v, ω, feasible, the nominal ω now, flags).

    A robot turning in place (|v̂| < l·|ω̂|: at its objective, looking) moves its look-ahead point sideways,
    and a teammate's barrier at its side, with a wall ahead holding v at 0, forbids one way of turning and
    not the other: the QP's nearest command was then no turn at all, for good (issue 34, the lab map:
    two robots at a door, each with its back to the other). Turning the other way gets there too (eq. 16
    asks k_ω times the angle; the long way is at least π, so π·k_ω, the bound).

    A robot that would give way to its teammate (:func:`_yield_direction`) turns the long way at once when
    it cannot: its drive away is held too (a wall), or no teammate's constraint binds its own command (no
    deadlock would ever be found). The other starts at a deadlock (:func:`filter_command`). The turn is
    kept (``memory``) until the law itself turns that way (past the far side) or stops turning in place,
    or the long way is held too. A deadlock's way out that ends so (not by the long way held) is a deadlock
    resolved."""
    ahead = safety.lookahead
    if not _in_place(v_hat, omega_hat, safety) or omega_hat * memory[TURNING] > 0.0:
        flags = DEADLOCK_RESOLVED if memory[TURNING] != 0 and memory[TURNING_OUT] == 1 else 0
        memory[TURNING] = memory[TURNING_OUT] = 0
        return v, omega, feasible, omega_hat, flags
    if memory[TURNING] == 0:
        if feasible and omega * omega_hat > 0.0 and abs(omega) >= HELD_FRACTION * abs(omega_hat):
            return v, omega, feasible, omega_hat, 0  # it turns as asked
        away_x, away_y = _yield_direction(me, poses, safety, False)
        if away_x == 0.0 and away_y == 0.0:
            return v, omega, feasible, omega_hat, 0  # the teammate, of the higher id, gives way (or none is near)
        v_away, omega_away, feasible_away = _drive_along(away_x, away_y, me, poses, ages, kinds, ground, cell, safety)
        if binding and feasible_away and math.hypot(v_away, ahead * omega_away) >= HELD_FRACTION * safety.v_max:
            return v, omega, feasible, omega_hat, 0  # it can give way: the deadlock's yield does that
    v_other, omega_other, feasible_other, turns = _long_way(
        v_hat, omega_hat, me, poses, ages, kinds, ground, cell, safety, memory
    )
    if turns:
        return v_other, omega_other, feasible_other, omega_other, 0
    return v, omega, feasible, omega_hat, 0


@njit(cache=True)
def _in_place(v_hat: float, omega_hat: float, safety: SafetyParameters) -> bool:
    """The law turns the robot in place: its look-ahead point moves mostly by turning, and more than a
    robot that does not want to move (WANTS_TO_MOVE)."""
    ahead = safety.lookahead
    return abs(v_hat) < ahead * abs(omega_hat) and ahead * abs(omega_hat) > WANTS_TO_MOVE * safety.v_max


@njit(cache=True)
def _long_way(
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
) -> tuple[float, float, bool, bool]:
    """The safe command for turning the long way round (the way in ``memory``, else against ω̂) at the bound,
    and whether it turns that way at HELD_FRACTION of |ω̂| or more: then ``memory`` keeps the way, else 0."""
    way = memory[TURNING] if memory[TURNING] != 0 else (-1 if omega_hat > 0.0 else 1)
    v, omega, feasible, _, _, _, _ = safe_velocities(
        v_hat, way * safety.omega_max, me, poses, ages, kinds, ground, cell, safety, 0.0
    )
    turns = feasible and omega * way >= HELD_FRACTION * abs(omega_hat)
    memory[TURNING] = way if turns else 0
    if not turns:
        memory[TURNING_OUT] = 0
    return v, omega, feasible, turns


@njit(cache=True)
def _detour(
    v_hat: float,
    omega_hat: float,
    v: float,
    omega: float,
    feasible: bool,
    passes: bool,
    me: int,
    poses: np.ndarray,
    ages: np.ndarray,
    kinds: np.ndarray,
    ground: Ground,
    cell: float,
    safety: SafetyParameters,
    memory: np.ndarray,
) -> tuple[float, float, bool, int]:
    """One step of a deadlock's detour: (v, ω, feasible, flags). Yielding drives away from the nearest
    (lower-id, or any on a relapse) teammate for YIELD_STEPS in all; keeping right ends once the law's
    command ``passes`` the filter (opening RELAPSE_STEPS in which the same deadlock found again is a
    relapse), or after DETOUR_STEPS."""
    if memory[YIELDING] != 0:
        away_x, away_y = _yield_direction(me, poses, safety, memory[YIELDING] == 2)
        if memory[DETOUR] >= YIELD_STEPS or (away_x == 0.0 and away_y == 0.0):
            memory[DETOUR] = memory[YIELDING] = 0
            return v, omega, feasible, DEADLOCK_RESOLVED if passes else 0
        memory[DETOUR] += 1
        v, omega, feasible = _drive_along(away_x, away_y, me, poses, ages, kinds, ground, cell, safety)
        return v, omega, feasible, KEEPING_RIGHT
    if passes:
        memory[DETOUR], memory[RELAPSE] = 0, RELAPSE_STEPS
        return v, omega, feasible, DEADLOCK_RESOLVED
    if memory[DETOUR] >= DETOUR_STEPS:
        memory[DETOUR] = 0
        return v, omega, feasible, 0
    memory[DETOUR] += 1
    v, omega, feasible, _, _, _, _ = safe_velocities(
        v_hat, omega_hat, me, poses, ages, kinds, ground, cell, safety, -KEEP_RIGHT
    )
    return v, omega, feasible, KEEPING_RIGHT


@njit(cache=True)
def _yield_direction(me: int, poses: np.ndarray, safety: SafetyParameters, any_id: bool) -> tuple[float, float]:
    """The unit vector from the nearest teammate's look-ahead point (within safety_range, centre to centre)
    to this robot's, when that teammate has the lower id or ``any_id`` (this robot yields); else (0, 0)."""
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
    if nearest < 0 or (nearest > me and not any_id):
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
