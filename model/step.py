"""One agent's control step, composed from the pure laws: read the map, decide, sense, move.

The in-process engine and the agent process both call these functions, so a
run over the bus and a run in one process execute the very same arithmetic.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from model.paper.control import combined_law, global_law, local_law, pursuit_law
from model.paper.dynamics import unicycle_step
from model.world.clearance import disk_is_free, step_or_stay
from model.world.ground import Ground
from model.world.occlusion import teammates_in_view
from model.world.wall_law import global_law_among_walls
from model.world.wedge import sense_wedge_among


class LawParameters(NamedTuple):
    """Everything the control law and the sensor need, in the paper's symbols and units."""

    sensing_range: float  # R
    half_angle: float  # F, radians
    alpha_max: float  # α_M
    beta: float  # β
    k_v: float
    k_omega: float
    dt: float
    cell: float
    target_ticks: int  # Λ* in fixed-point ticks
    literal_heading: bool  # eq. 11 as printed
    literal_omega: bool  # eq. 16 as printed
    pursuit: bool = False  # the anicov controller: pure pursuit of a carrot (model.paper.control.pursuit_law)
    weave_amplitude: float = 0.0  # the anicov controller's weave, radians (model.controllers.anicov.weave; 0: straight)
    weave_wavelength: float = 1.0  # its wavelength, units
    face_radius: float = 0.0  # the anicov controller's stations: a carrot this near is a bearing to face (0: none)
    position_doubt: float = 0.0  # how far off its belief a robot may stand: its map takes the sure coverage (0: exact)
    heading_doubt: float = 0.0  # and how far its heading may be off, radians (model.paper.sensing.sure_sensing_ability)
    face_turn_steps: float = 1.0  # steps a robot at its station takes to turn to a bearing: 1 + its commands' delay


@njit(cache=True)
def read_wedge(
    coverage: np.ndarray,
    x: float,
    y: float,
    theta: float,
    law: LawParameters,
    ground: Ground,
    teammates: np.ndarray,
) -> tuple[float, float, float, int, int, np.ndarray]:
    """:func:`model.world.wedge.sense_wedge` with the law's sensor, ``teammates`` those that may hide part of
    the wedge (:func:`model.world.occlusion.teammates_in_view`)."""
    return sense_wedge_among(
        coverage,
        law.target_ticks,
        x,
        y,
        theta,
        law.sensing_range,
        law.half_angle,
        law.alpha_max,
        law.dt,
        law.cell,
        ground,
        teammates,
        (law.position_doubt, law.heading_doubt),
    )


def no_look() -> np.ndarray:
    """A robot's ``look`` for :func:`decide_and_sense` before its first step: it has looked at nothing."""
    return np.full(2, np.nan)


@njit(cache=True)
def pursue(
    x: float, y: float, theta: float, objective_x: float, objective_y: float, law: LawParameters
) -> tuple[float, float]:
    """(v, ω) of the anicov controller's law (:func:`model.paper.control.pursuit_law`) toward ``objective``, with
    ``law``'s gains, time step and weave."""
    return pursuit_law(
        x, y, theta, objective_x, objective_y, law.k_v, law.k_omega, law.dt, law.weave_amplitude,
        law.weave_wavelength, law.face_radius, law.face_turn_steps,
    )  # fmt: skip


@njit(cache=True)
def decide_and_sense(
    coverage: np.ndarray,
    x: float,
    y: float,
    theta: float,
    objective_x: float,
    objective_y: float,
    law: LawParameters,
    ground: Ground,
    field: np.ndarray,
    positions: np.ndarray,
    me: int,
    look: np.ndarray,
) -> tuple[float, float, float, int, int, np.ndarray]:
    """(v, ω, e_Ω) of one agent from its map and objective (eq. 6–16), and its delta window (eq. 3).

    On a terrain: ``field`` is the geodesic distance field of the objective (the global law follows the
    shortest free path when a wall hides it), ``positions`` (N, 2) every robot's position with this
    one's at row ``me`` (teammates hide cells), ``look`` (2,) the cell this robot looked at in the step before
    (:func:`model.world.wall_law.cell_to_look_at`; NaN: none; the law writes it); in the open world none is read."""
    teammates = teammates_in_view(ground, positions, me, x, y, law.sensing_range)
    e_omega, w_left, w_right, row0, col0, ticks = read_wedge(coverage, x, y, theta, law, ground, teammates)
    if law.pursuit:
        v, omega = pursue(x, y, theta, objective_x, objective_y, law)
        return v, omega, e_omega, row0, col0, ticks
    u_loc, theta_loc = local_law(e_omega, w_left, w_right, theta, law.half_angle)
    u_glo, theta_glo = global_law(x, y, objective_x, objective_y, law.sensing_range, law.literal_heading)
    if ground.walls:
        u_glo, theta_glo = global_law_among_walls(
            coverage,
            law.target_ticks,
            x,
            y,
            objective_x,
            objective_y,
            u_glo,
            theta_glo,
            law.sensing_range,
            law.cell,
            law.literal_heading,
            ground,
            field,
            teammates,
            look,
        )
    v, omega = combined_law(
        theta, e_omega, u_loc, theta_loc, u_glo, theta_glo, law.beta, law.k_v, law.k_omega, law.literal_omega
    )
    if (ground.walls or ground.bounded) and not _step_is_free(x, y, theta, v, omega, law, ground):
        # The weighted laws push into a wall (they can balance there: e_θ = 0 with v > 0, for ever).
        # Take the global law alone, W_glo = 1 (eq. 12-16 with e_Ω = 0): it follows the free path.
        v, omega = combined_law(
            theta, 0.0, u_loc, theta_loc, u_glo, theta_glo, law.beta, law.k_v, law.k_omega, law.literal_omega
        )
    return v, omega, e_omega, row0, col0, ticks


@njit(cache=True)
def _step_is_free(x: float, y: float, theta: float, v: float, omega: float, law: LawParameters, ground: Ground) -> bool:
    next_x, next_y, _ = unicycle_step(x, y, theta, v, omega, law.dt)
    return disk_is_free(ground.wall_grid, next_x, next_y, ground.wall_clearance, ground.grain, ground.bounded)


def load_kernels(coverage: np.ndarray, pose: tuple[float, float, float], law: LawParameters, ground: Ground) -> None:
    """Have numba load the control kernels now, with the argument types of the real calls (half a second
    from its cache at the first call), on a scratch map: nothing of the agent's state changes."""
    x, y, theta = pose
    positions = np.array([[x, y]])
    field = np.zeros(ground.occupied.shape)
    v, omega, _, _, _, _ = decide_and_sense(
        np.zeros_like(coverage), x, y, theta, x + 1.0, y, law, ground, field, positions, 0, no_look()
    )
    move(x, y, theta, v, omega, law, ground)


@njit(cache=True)
def sense_only(
    coverage: np.ndarray,
    x: float,
    y: float,
    theta: float,
    law: LawParameters,
    ground: Ground,
    positions: np.ndarray,
    me: int,
) -> tuple[int, int, np.ndarray]:
    """The delta window of an agent whose velocities come from elsewhere (the zig-zag pilot)."""
    teammates = teammates_in_view(ground, positions, me, x, y, law.sensing_range)
    _, _, _, row0, col0, ticks = read_wedge(coverage, x, y, theta, law, ground, teammates)
    return row0, col0, ticks


@njit(cache=True)
def move(
    x: float, y: float, theta: float, v: float, omega: float, law: LawParameters, ground: Ground
) -> tuple[float, float, float]:
    """The pose after one step, eq. 1; on a terrain a step that would put the disk over a wall (or off
    the map) is not taken as a move, only as a turn (:func:`model.world.clearance.step_or_stay`)."""
    if ground.walls or ground.bounded:
        return step_or_stay(
            ground.wall_grid, x, y, theta, v, omega, law.dt, ground.radius, ground.grain, ground.bounded
        )
    return unicycle_step(x, y, theta, v, omega, law.dt)
