"""The coverage control law of Section III: local (eq. 7–9), global (eq. 10–11), combined (eq. 12–16).

Two readings of the paper are selectable (see docs/paper-notes.md):

- ``literal_heading``: eq. 11 as printed, θ_glo* = atan2(p_i − p_obj), which
  points *away* from the objective; otherwise atan2(p_obj − p_i).
- ``literal_omega``: eq. 16 as printed, ω = k_ω e_θ (1 − u_glo); otherwise
  ω = k_ω e_θ, which keeps the stated bound |ω| ≤ k_ω π and lets an agent
  far from its objective turn.
"""

from __future__ import annotations

import math

from numba import njit

from model.paper.geometry import wrap_angle


@njit(cache=True)
def local_law(e_omega: float, w_left: float, w_right: float, theta: float, half_angle: float) -> tuple[float, float]:
    """Local law (u_loc, θ_loc*), eq. 7–9.

    u_loc = 1 − e_Ω (eq. 7). Eq. 9 gives the derivative of the covering rate
    with respect to θ_i, not a heading; we take a normalised gradient step:
    θ_loc* = θ_i + F (w_left − w_right)/(w_left + w_right), so a view that is
    uncovered on one side only turns the heading by the half angle F toward
    it, and a balanced view (∂ẽ/∂θ_i = 0) keeps it.
    """
    u_loc = 1.0 - e_omega
    total = w_left + w_right
    if total <= 0.0:
        return u_loc, theta
    return u_loc, wrap_angle(theta + half_angle * (w_left - w_right) / total)


@njit(cache=True)
def global_law(
    x: float, y: float, objective_x: float, objective_y: float, sensing_range: float, literal_heading: bool
) -> tuple[float, float]:
    """Global law (u_glo, θ_glo*), eq. 10–11: speed from distance to the objective, heading toward it."""
    dx = objective_x - x
    dy = objective_y - y
    u_glo = (2.0 / math.pi) * math.atan(math.sqrt(dx * dx + dy * dy) - sensing_range / 2.0)
    if literal_heading:
        return u_glo, math.atan2(-dy, -dx)
    return u_glo, math.atan2(dy, dx)


@njit(cache=True)
def global_law_around_walls(
    x: float,
    y: float,
    waypoint_x: float,
    waypoint_y: float,
    distance: float,
    literal_heading: bool,
) -> tuple[float, float]:
    """Eq. 10–11 on a terrain where a straight drive to the objective would hit a wall: the heading toward
    the waypoint of the shortest free path (:func:`model.world.geodesic.descent_waypoint`), u_glo from its
    length ``distance`` without eq. 10's stop at R/2. That stop frames the objective in the wedge, which
    the way round a wall does not: a robot stopped R/2 away by path would wait there for ever (and one
    stopping only when the objective is in line of sight, heading for the waypoint, rocks back and
    forth on that line). Once a straight drive gets there, eq. 10 applies as printed."""
    u_glo = (2.0 / math.pi) * math.atan(distance)
    dx = waypoint_x - x
    dy = waypoint_y - y
    if literal_heading:
        return u_glo, math.atan2(-dy, -dx)
    return u_glo, math.atan2(dy, dx)


@njit(cache=True)
def pursuit_law(
    x: float,
    y: float,
    theta: float,
    objective_x: float,
    objective_y: float,
    k_v: float,
    k_omega: float,
    dt: float,
    weave_amplitude: float = 0.0,
    weave_wavelength: float = 1.0,
    face_radius: float = 0.0,
    face_turn_steps: float = 1.0,
) -> tuple[float, float]:
    """Beyond the paper, the ``anicov`` controller (docs/controller.md): drive at the objective, a carrot
    on the planned path (pure pursuit, Coulter 1992), at full speed until the carrot is within one step,
    with eq. 15-16's heading terms: v = k_v min(1, d/(k_v dt)) (1 − 2|e_θ|/π), ω = k_ω e_θ, e_θ the
    wrapped heading error to the carrot, d its distance. |v| ≤ k_v and |ω| ≤ π k_ω, the paper's bounds
    (a carrot behind the robot makes it back up while it turns, as eq. 15 does).

    With a weave (``weave_amplitude`` A > 0, :mod:`model.controllers.anicov.weave`): the heading is steered to the carrot's
    bearing plus A sin(2π s/λ), s the robot's coordinate along the axis nearer the carrot's direction (the
    spiral's sides are axis-parallel; a stateless phase, the same in every process), with the reference's
    own rate fed forward, ω = k_ω e_θ + A cos(2π s/λ) (2π/λ) ds/dt, held to |ω| ≤ π k_ω; the speed drops
    only for the part of the bearing error beyond A: v = k_v min(1, d/(k_v dt)) (1 − 2 max(0, |e_b| − A)/π).
    With A = 0 this is the law above.

    A carrot nearer than ``face_radius`` (> 0; a robot at a station, :mod:`model.controllers.anicov.stations`) is a bearing to
    face, not a place to go: the robot stands (v = 0) and turns toward the carrot's bearing at the bound,
    ω = e_θ/(s dt) held to |ω| ≤ π k_ω, s = ``face_turn_steps`` (1: it reaches the bearing within the step where it
    can; a robot whose commands reach its wheels d steps late turns over 1 + d: turning the whole error each step, it
    would turn it again before the first turn acted, and swing by e_θ for ever). With ``face_radius`` = 0 (every
    sweep but the stations) this never applies."""
    dx = objective_x - x
    dy = objective_y - y
    bearing = math.atan2(dy, dx)
    if dx * dx + dy * dy < face_radius * face_radius:
        bound = math.pi * k_omega
        return 0.0, min(bound, max(-bound, wrap_angle(bearing - theta) / (dt * face_turn_steps)))
    along_x = abs(dx) >= abs(dy)
    phase = 2.0 * math.pi * (x if along_x else y) / weave_wavelength
    e_theta = wrap_angle(bearing + weave_amplitude * math.sin(phase) - theta)
    arrive = min(1.0, math.sqrt(dx * dx + dy * dy) / (k_v * dt))
    beyond_weave = max(0.0, abs(wrap_angle(bearing - theta)) - weave_amplitude)
    # Held at -1: at |e_θ| one ulp from π the product (2/π)|e_θ| rounds past 2 (hypothesis found
    # v = -1.0000000000000004 at θ = 3.1415926535897927 with the carrot straight behind).
    heading = max(-1.0, 1.0 - (2.0 / math.pi) * beyond_weave)
    v = k_v * arrive * heading
    travel_rate = v * (math.cos(theta) if along_x else math.sin(theta))  # ds/dt
    feed_forward = weave_amplitude * math.cos(phase) * (2.0 * math.pi / weave_wavelength) * travel_rate
    bound = math.pi * k_omega
    return v, min(bound, max(-bound, k_omega * e_theta + feed_forward))


@njit(cache=True)
def combined_law(
    theta: float,
    e_omega: float,
    u_loc: float,
    theta_loc: float,
    u_glo: float,
    theta_glo: float,
    beta: float,
    k_v: float,
    k_omega: float,
    literal_omega: bool,
) -> tuple[float, float]:
    """Velocities (v, ω) from the weighted laws, eq. 12–16.

    W_loc = e_Ω^β, W_glo = 1 − W_loc (eq. 12–13); e_θ is the weighted sum of
    the wrapped heading errors (eq. 14). Eq. 15 uses |e_θ| so that
    v ∈ [−k_v, k_v] as the paper states.
    """
    w_loc = e_omega**beta
    w_glo = 1.0 - w_loc
    e_theta = wrap_angle(theta_loc - theta) * w_loc + wrap_angle(theta_glo - theta) * w_glo
    v = k_v * (u_loc * w_loc + u_glo * w_glo) * (1.0 - (2.0 / math.pi) * abs(e_theta))
    if literal_omega:
        omega = k_omega * e_theta * (1.0 - u_glo)
    else:
        omega = k_omega * e_theta
    return v, omega
