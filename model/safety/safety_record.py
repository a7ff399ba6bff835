"""What a run shows of safety (issue 12), from its trace and the filter's flags: the figures summary.json
reports whenever robots have a body, with the filter on or off (so the two can be compared).

- ``min_separation``: the least distance between two robots' centres, over every step and along the
  straight line between consecutive poses (the closest approach of two linear motions; a unicycle's arc
  departs from its chord by at most v·ω·dt²/8, 0.004 units at the paper's gains). Safe: ≥ 2r. Realtime,
  on the wall clock instead: each state carries the time its robot reached its pose (one host's clock,
  or clocks kept in sync), the positions of each robot are joined by straight lines in time and every
  pair is compared at the union of their times (states that never reached the coordinator are bridged).
- ``min_clearance``: the least distance from a centre to an occupied cell (or, on a map, its edge), at
  every pose of the trace. Safe: ≥ r. None in the open world.
- ``filter_active_fraction``: the share of agent-steps whose command the filter changed or stopped.
- ``deadlocks`` / ``deadlocks_resolved``: robots held still by a teammate long enough to start a detour,
  and the detours that ended with the law's own command passing again (model.safety.safety).
- ``late_steps``: realtime, agent-steps taken standing still because the control loop fell a period
  behind its clock (0 in lockstep and in the engine).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from model.safety.safety import (
    DEADLOCK_FOUND,
    DEADLOCK_RESOLVED,
    FILTER_CHANGED,
    KEEPING_RIGHT,
    NO_SAFE_COMMAND,
    RAN_LATE,
    STALE_NEIGHBOUR,
)
from model.world.clearance import clearance_within
from model.world.ground import Ground

ACTIVE = FILTER_CHANGED | KEEPING_RIGHT | NO_SAFE_COMMAND | STALE_NEIGHBOUR


def fill_unheard(positions: np.ndarray) -> np.ndarray:
    """A realtime trace's positions with the steps never heard (NaN) filled by straight-line interpolation
    between the heard ones of the same robot (before the first and after the last: left NaN)."""
    if np.isfinite(positions).all():
        return positions
    filled = positions.copy()
    steps = np.arange(len(positions))
    for agent in range(positions.shape[1]):
        heard = np.isfinite(positions[:, agent, 0])
        if heard.sum() >= 2:
            inside = (steps >= steps[heard][0]) & (steps <= steps[heard][-1])
            for axis in (0, 1):
                filled[inside, agent, axis] = np.interp(steps[inside], steps[heard], positions[heard, agent, axis])
    return filled


def min_separation(positions: np.ndarray) -> float | None:
    """Least centre distance over the (steps, N, 2) positions and the segments between them (a realtime
    trace's unheard steps interpolated, :func:`fill_unheard`). None with fewer than two robots."""
    agents = positions.shape[1]
    if agents < 2 or len(positions) == 0:
        return None
    positions = fill_unheard(positions)
    first, second = np.triu_indices(agents, 1)
    least = _closest_approach(positions[:, first] - positions[:, second])  # (steps, pairs, 2)
    return least if math.isfinite(least) else None


def _closest_approach(relative: np.ndarray) -> float:
    """Least |r| over relative positions (M, ..., 2) in time order and the straight segments between
    consecutive ones (the closest approach of two linear motions); NaN entries are skipped."""
    distances = np.linalg.norm(relative, axis=-1)
    least = float(np.nanmin(distances)) if np.isfinite(distances).any() else math.inf
    if len(relative) > 1:
        start, motion = relative[:-1], relative[1:] - relative[:-1]
        length2 = np.sum(motion * motion, axis=-1)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.clip(-np.sum(start * motion, axis=-1) / length2, 0.0, 1.0)
        t = np.where(length2 > 0.0, t, 0.0)
        closest = np.linalg.norm(start + t[..., None] * motion, axis=-1)
        if np.isfinite(closest).any():
            least = min(least, float(np.nanmin(closest)))
    return least


def min_separation_in_time(timed: dict[int, np.ndarray]) -> float | None:
    """Realtime: the least centre distance with every robot's positions on one wall clock, each
    robot's (time, x, y) after its steps joined by straight lines, over the times both of a pair were
    heard. None with fewer than two robots heard."""
    least = math.inf
    agents = sorted(agent for agent, rows in timed.items() if len(rows) >= 2)
    for index, first in enumerate(agents):
        a = timed[first][np.argsort(timed[first][:, 0], kind="stable")]
        for second in agents[index + 1 :]:
            b = timed[second][np.argsort(timed[second][:, 0], kind="stable")]
            times = np.union1d(a[:, 0], b[:, 0])
            times = times[(times >= max(a[0, 0], b[0, 0])) & (times <= min(a[-1, 0], b[-1, 0]))]
            if len(times) == 0:
                continue
            dx = np.interp(times, a[:, 0], a[:, 1]) - np.interp(times, b[:, 0], b[:, 1])
            dy = np.interp(times, a[:, 0], a[:, 2]) - np.interp(times, b[:, 0], b[:, 2])
            least = min(least, _closest_approach(np.stack([dx, dy], axis=1)))
    return least if math.isfinite(least) else None


@njit(cache=True)
def _least_clearance(
    occupied: np.ndarray, xs: np.ndarray, ys: np.ndarray, cap: float, cell: float, bounded: bool
) -> float:
    least = cap
    for k in range(xs.shape[0]):
        if math.isfinite(xs[k]) and math.isfinite(ys[k]):
            least = min(least, clearance_within(occupied, xs[k], ys[k], least, cell, bounded))
    return least


def min_clearance(positions: np.ndarray, ground: Ground, cell: float) -> float | None:
    """Least distance from a centre to a wall (or a map's edge) over the (steps, N, 2) positions; None
    when there is neither."""
    if not ground.occupied.any() and not ground.bounded:
        return None
    cap = float(max(ground.occupied.shape) * cell)
    xs, ys = positions[..., 0].ravel(), positions[..., 1].ravel()
    return float(_least_clearance(ground.wall_grid, xs, ys, cap, ground.grain, ground.bounded))


def safety_figures(
    positions: np.ndarray,
    flags: np.ndarray | None,
    ground: Ground,
    cell: float,
    timed: dict[int, np.ndarray] | None = None,
) -> dict[str, object]:
    """The summary.json safety figures of a run (see the module docstring); ``timed``: a realtime run's
    stamped positions, from which min_separation is taken on the wall clock."""
    flags = np.zeros((0, positions.shape[1]), dtype=np.uint8) if flags is None else flags
    heard = np.isfinite(positions[: len(flags), :, 0]) if len(flags) else np.zeros(flags.shape, dtype=bool)
    steps = int(heard.sum())
    return {
        "min_separation": min_separation(positions) if timed is None else min_separation_in_time(timed),
        "min_clearance": min_clearance(positions, ground, cell),
        "filter_active_fraction": float(((flags & ACTIVE) != 0)[heard].sum() / steps) if steps else 0.0,
        "deadlocks": int(((flags & DEADLOCK_FOUND) != 0).sum()),
        "deadlocks_resolved": int(((flags & DEADLOCK_RESOLVED) != 0).sum()),
        "late_steps": int(((flags & RAN_LATE) != 0).sum()),
    }
