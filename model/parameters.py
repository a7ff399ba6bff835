"""From a scenario to what one agent needs: its control-law parameters and its initial pose.

Kept apart from the engine so that an agent process imports only what it runs.
"""

from __future__ import annotations

import math

import numpy as np

from model.paper.coverage_map import CoverageMap
from model.radio.exact_coverage import ExactKernel, exact_kernel
from model.safety.safety import SafetyParameters, disabled_safety
from model.scenario import Scenario
from model.scenario.physics_keys import cover_margin_of, pair_margin_of, safety_margin_of
from model.scenario.safety_keys import point_speed
from model.world.clearance import disk_is_free
from model.world.world import map_frame_of, world_of


def exact_kernel_of(scenario: Scenario) -> ExactKernel | None:
    """The integer coverage kernel of a scenario's sensor and grid (model.radio.exact_coverage), or None where
    its numbers do not fit (a domain or range over 2²⁰ units): deltas then travel as cells."""
    try:
        return exact_kernel(
            *scenario.grid_shape, scenario.cell, scenario.range, scenario.half_angle, scenario.alpha_max, scenario.dt
        )
    except ValueError:
        return None


def coverage_map_of(scenario: Scenario, with_margin: bool = True) -> CoverageMap:
    """A fresh map of the scenario's grid, started as its world says (:meth:`model.world.world.World.head_start`:
    cells nobody can cover are out of e_D; a priority map's cells start part-way). With noise
    (:func:`model.scenario.physics_keys.cover_margin_of`) the team's map asks (1 + ``cover_margin``) Λ* of every cell, whichever process
    keeps it, but for the cells it cannot surely see (:attr:`model.world.world.World.unsure`), which it does not
    ask; ``with_margin=False``: Λ* of every coverable cell, the truth's map."""
    rows, cols = scenario.grid_shape
    margin = cover_margin_of(scenario) if with_margin else 0.0
    coverage_map = CoverageMap(rows, cols, scenario.cell, scenario.lambda_star * (1.0 + margin))
    world = world_of(scenario)
    if not world.open or scenario.priority_map:
        start = world.head_start(coverage_map.target_ticks, 1.0 + margin)
        if with_margin:  # the team does not ask what it cannot surely see; the truth's map still counts it
            start[world.unsure] = coverage_map.target_ticks
        coverage_map.start_from(start)
    return coverage_map


def initial_poses(scenario: Scenario) -> np.ndarray:
    """Poses (N, 3) drawn uniformly in the domain and in (−π, π] from the scenario's seed."""
    rng = np.random.default_rng(scenario.seed)
    width, height = scenario.domain
    x = rng.uniform(0.0, width, scenario.agents)
    y = rng.uniform(0.0, height, scenario.agents)
    theta = rng.uniform(-math.pi, math.pi, scenario.agents)
    return np.stack([x, y, theta], axis=1)


POSE_ATTEMPTS = 10_000
"""Draws per robot before the free space is declared too small for the team."""


def free_initial_poses(
    occupied: np.ndarray,
    cell: float,
    agents: int,
    seed: int,
    radius: float,
    clearance: float,
    reachable: np.ndarray | None = None,
    spacing: float | None = None,
    clear_edges: bool = False,
    reachable_cell: float | None = None,
) -> np.ndarray:
    """Poses (N, 3) drawn from ``seed`` as :func:`initial_poses` draws them (all x, all y, all θ, over
    the grid's extent), keeping each robot whose disk is on the grid, ``clearance`` away from occupied
    squares of side ``cell`` (and, ``clear_edges``, from the grid's edge), at least 2·radius + ``spacing``
    (default: clearance) from the robots kept before it, and (given ``reachable``, on cells of
    ``reachable_cell``, default ``cell``) in a reachable cell; the others are drawn again, in rounds, in id order. On a grid with no occupied cell
    and point robots every pose is kept at once: the poses are exactly :func:`initial_poses`'s. Raises
    ValueError when the free space cannot hold the team."""
    rng = np.random.default_rng(seed)
    spacing = clearance if spacing is None else spacing
    reach_cell = cell if reachable_cell is None else reachable_cell
    rows, cols = occupied.shape
    poses = np.zeros((agents, 3))
    placed: list[int] = []
    pending = list(range(agents))
    for _ in range(POSE_ATTEMPTS):
        if not pending:
            return poses
        xs = rng.uniform(0.0, cols * cell, len(pending))
        ys = rng.uniform(0.0, rows * cell, len(pending))
        thetas = rng.uniform(-math.pi, math.pi, len(pending))
        still: list[int] = []
        for agent, x, y, theta in zip(pending, xs, ys, thetas, strict=True):
            if _start_is_free(occupied, cell, x, y, radius, clearance, reachable, reach_cell, clear_edges) and all(
                math.hypot(x - poses[other, 0], y - poses[other, 1]) >= 2.0 * radius + spacing for other in placed
            ):
                poses[agent] = (x, y, theta)
                placed.append(agent)
            else:
                still.append(agent)
        pending = still
    raise ValueError(
        f"no free place for robot {pending[0]} of {agents} after {POSE_ATTEMPTS} draws: the free space "
        f"cannot hold {agents} robots of radius {radius} with clearance {clearance}"
    )


def _start_is_free(
    occupied: np.ndarray,
    cell: float,
    x: float,
    y: float,
    radius: float,
    clearance: float,
    reachable: np.ndarray | None,
    reachable_cell: float,
    clear_edges: bool,
) -> bool:
    if not disk_is_free(occupied, x, y, radius, cell, True):
        return False
    if clearance > 0.0 and not disk_is_free(occupied, x, y, radius + clearance, cell, clear_edges):
        return False
    if reachable is None:
        return True
    rows, cols = reachable.shape
    return bool(reachable[min(int(y / reachable_cell), rows - 1), min(int(x / reachable_cell), cols - 1)])


START_CLEARANCE = 0.5
"""Free distance, in cells, between a robot's disk and the nearest wall (or teammate) at the start."""


def starting_poses(scenario: Scenario) -> np.ndarray:
    """The team's poses at t_0: :func:`initial_poses` in the open world; on a terrain drawn in the team's
    space, clear of walls and of each other (:func:`free_initial_poses`). ValueError: no room."""
    if scenario.initial_poses:  # in the map's frame, with a map (model.scenario.safety_keys)
        frame = map_frame_of(scenario)
        given = np.array(scenario.initial_poses, dtype=np.float64)
        model_x, model_y = frame.from_map(given[:, 0], given[:, 1])
        return np.stack([model_x, model_y, frame.heading_from_map(np.radians(given[:, 2]))], axis=1)
    world = world_of(scenario)
    if world.open:
        return initial_poses(scenario)
    clearance = spacing = START_CLEARANCE * scenario.cell
    if (
        scenario.filters
    ):  # every barrier holds at t_0 (model.safety.safety): points 2r + s + 2l apart, disks s off walls
        clearance = max(clearance, safety_margin_of(scenario))
        spacing = max(spacing, pair_margin_of(scenario) + 4.0 * scenario.lookahead)
    return free_initial_poses(
        world.wall_grid,
        world.grain,
        scenario.agents,
        scenario.seed,
        scenario.robot_radius,
        clearance,
        world.reachable,
        spacing,
        clear_edges=scenario.filters and world.ground.bounded,
        reachable_cell=scenario.cell,
    )


def safety_parameters(scenario: Scenario) -> SafetyParameters:
    """The safety filter's constants (model.safety.safety); disabled for point robots or ``safety = false``."""
    if not scenario.filters:
        return disabled_safety()
    omega_max = math.pi * scenario.k_omega
    fastest = point_speed(scenario.k_v, scenario.k_omega, scenario.lookahead)
    return SafetyParameters(
        enabled=True,
        radius=scenario.robot_radius,
        margin=safety_margin_of(scenario),
        lookahead=scenario.lookahead,
        decay=min(1.0, scenario.barrier_gain * scenario.dt),
        reach=scenario.safety_range,
        v_max=scenario.k_v,
        omega_max=omega_max,
        dt=scenario.dt,
        point_speed=fastest,
        slack=fastest * omega_max * scenario.dt**2 / 2.0,
        max_pose_age=scenario.max_pose_age,
        pair_margin=pair_margin_of(scenario),
    )
