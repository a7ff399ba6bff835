"""Algorithm 2: greedy assignment of objectives on the normalised distance matrix (eq. 17)."""

from __future__ import annotations

import numpy as np


def normalised_distances(agent_positions: np.ndarray, objectives: np.ndarray) -> np.ndarray:
    """D(i, j) = ‖p_i − ψ_j‖ / max ‖p_i − ψ_j‖, eq. 17 (all entries in [0, 1])."""
    return normalised(np.linalg.norm(agent_positions[:, None, :] - objectives[None, :, :], axis=2))


def normalised(distances: np.ndarray) -> np.ndarray:
    """Eq. 17 on any distances (straight, or geodesic around walls): divided by the largest finite one.
    An objective an agent cannot reach (+inf) counts as far as the farthest, D = 1."""
    finite = np.isfinite(distances)
    largest = distances[finite].max() if finite.any() else 0.0
    matrix = distances / largest if largest > 0.0 else np.where(finite, distances, 0.0)
    return np.where(finite, matrix, 1.0)


def assign_objectives(
    agent_positions: np.ndarray, objectives: np.ndarray, distances: np.ndarray | None = None
) -> np.ndarray:
    """Index of the objective given to each agent, Algorithm 2.

    Repeatedly take the smallest entry (i, j) of D, give ψ_j to agent i, then
    add a large number to row i (agent i is done) and add to column j (ψ_j is
    less attractive to the rest). The paper adds N and 1; since an entry of D
    may be exactly 1 (the farthest pair) or 0 (an agent on an objective), a
    column raised by 1 could tie with an untaken one, so we add 2 to columns
    and 2N + 1 to rows: strictly, an objective taken k times loses to any
    taken fewer times, and each objective gets ⌊N/M⌋ to ⌈N/M⌉ agents.
    ``distances`` (N, M), when given, replaces the straight distances (e.g. geodesic ones on a map).
    """
    agent_count = len(agent_positions)
    if len(objectives) == 0:
        raise ValueError("assign_objectives needs at least one objective")
    matrix = normalised_distances(agent_positions, objectives) if distances is None else normalised(distances)
    choice = np.full(agent_count, -1, dtype=np.int64)
    for _ in range(agent_count):
        i, j = np.unravel_index(int(np.argmin(matrix)), matrix.shape)
        choice[i] = j
        matrix[i, :] += 2 * agent_count + 1
        matrix[:, j] += 2.0
    return choice
