"""Algorithm 1: global objectives from blobs of uncovered cells (Section IV).

Objectives Ψ and their blobs π_j persist between calls. Each call

1. drops objectives whose own cell is covered (lines 1–5) and objectives
   whose nearest other objective is closer than R (lines 6–13), releasing
   their cells;
2. finds blobs (8-connected components) of uncovered, unassigned cells
   (line 14, 16) and keeps a blob only if its centroid falls inside it
   (line 18, read as "ψ^k ∈ π^k");
3. erodes what is left and repeats until nothing is left (lines 15–24), so
   irregular blobs (rings, C and L shapes, Fig. 3) shrink until their
   centroids land on uncovered cells;
4. gives the eroded cells to the nearest blob (line 25). On a terrain (``by_paths``) "nearest" is
   taken through uncovered cells, not across walls: an eroded cell goes to the blob its uncovered
   region reaches first (:func:`by_paths_through`), and what reaches none forms blobs of its own.
   The straight nearest blob gave a room's leftovers to the blobs of the rooms beside it, whose
   objectives held them while the room waited (docs/terrain.md).

If no objective survives while cells are still uncovered (a symmetric map
that erodes away entirely), the uncovered cell nearest to the team is the
single objective until the symmetry breaks.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
from scipy import ndimage

_ERODE_KERNEL = np.ones((3, 3), dtype=np.uint8)


@dataclass
class BlobObjectives:
    """Ψ (objective positions, world units) and the blob label of every cell (0 = none, j+1 = π_j)."""

    positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    labels: np.ndarray | None = None
    cells: np.ndarray | None = None
    """(M, 2) int (row, col): the blob's cell each objective was found in (line 18's test: the centroid
    rounded to a cell). A centroid may lie on a cell's edge or corner, so the cell its point falls in
    (:func:`cell_of`) can be another cell, even a wall's; a viewpoint on a terrain is found for this one."""

    @property
    def count(self) -> int:
        return len(self.positions)


def cell_of(point: np.ndarray, cell: float, shape: tuple[int, int]) -> tuple[int, int]:
    """(row, col) of the grid cell containing a world point, clamped to the grid."""
    row = min(max(int(point[1] // cell), 0), shape[0] - 1)
    col = min(max(int(point[0] // cell), 0), shape[1] - 1)
    return row, col


def _keep_objectives(previous: BlobObjectives, lack: np.ndarray, cell: float, merge_distance: float) -> list[int]:
    """Indices of previous objectives that survive lines 1–13."""
    uncovered = [j for j, point in enumerate(previous.positions) if lack[cell_of(point, cell, lack.shape)] > 0.0]
    if len(uncovered) < 2:
        return uncovered
    points = previous.positions[uncovered]
    gaps = np.linalg.norm(points[:, None, :] - points[None, :, :], axis=2)
    np.fill_diagonal(gaps, np.inf)
    nearest = gaps.min(axis=1)
    return [j for j, gap in zip(uncovered, nearest, strict=True) if gap >= merge_distance]


def select_objectives(
    lack: np.ndarray,
    previous: BlobObjectives,
    cell: float,
    merge_distance: float,
    by_paths: bool = False,
) -> BlobObjectives:
    """Algorithm 1 on the lack-of-coverage map Υ; ``merge_distance`` is R. ``by_paths`` (a terrain with
    walls): line 25 through uncovered cells (:func:`by_paths_through`); the paper's empty domain keeps
    the straight nearest blob."""
    kept = _keep_objectives(previous, lack, cell, merge_distance) if previous.count else []
    labels = np.zeros(lack.shape, dtype=np.int32)
    positions: list[np.ndarray] = []
    cells: list[tuple[int, int]] = []
    if kept and previous.labels is not None:
        relabel = np.zeros(previous.count + 1, dtype=np.int32)
        for new_index, j in enumerate(kept):
            relabel[j + 1] = new_index + 1
            positions.append(previous.positions[j])
            known = previous.cells is not None and len(previous.cells) == previous.count
            cells.append(tuple(previous.cells[j]) if known else cell_of(previous.positions[j], cell, lack.shape))
        labels = relabel[previous.labels]

    uncovered = lack > 0.0
    blob_domain = (uncovered & (labels == 0)).astype(np.uint8)
    while blob_domain.any():
        count, components, stats, centroids = cv2.connectedComponentsWithStats(blob_domain, connectivity=8)
        for k in range(1, count):
            cx, cy = centroids[k]
            row, col = round(cy), round(cx)
            if components[row, col] != k:
                continue
            left, top, width, height = stats[k, :4]
            window = components[top : top + height, left : left + width] == k
            label = len(positions) + 1
            labels[top : top + height, left : left + width][window] = label
            blob_domain[top : top + height, left : left + width][window] = 0
            positions.append(np.array([(cx + 0.5) * cell, (cy + 0.5) * cell]))
            cells.append((row, col))
        blob_domain = cv2.erode(blob_domain, _ERODE_KERNEL)

    eroded = uncovered & (labels == 0)
    if by_paths and eroded.any():
        labels = by_paths_through(uncovered, labels, eroded, positions, cell, cells)
    elif positions and eroded.any():
        _, nearest = ndimage.distance_transform_edt(labels == 0, return_indices=True)
        labels[eroded] = labels[nearest[0][eroded], nearest[1][eroded]]
    stacked = np.array(positions, dtype=np.float64).reshape(-1, 2)
    return BlobObjectives(positions=stacked, labels=labels, cells=np.array(cells, dtype=np.int64).reshape(-1, 2))


def by_paths_through(
    uncovered: np.ndarray,
    labels: np.ndarray,
    eroded: np.ndarray,
    positions: list[np.ndarray],
    cell: float,
    cells: list[tuple[int, int]] | None = None,
) -> np.ndarray:
    """Line 25 on a terrain: each eroded cell takes the label of the blob that reaches it first by
    8-connected steps through uncovered cells (a wavefront from every blob at once; the larger label on
    a tie, so every replica gets the same); each region of eroded cells no blob reaches becomes a blob of
    its own, its objective (appended to ``positions``, its cell to ``cells``) the region's cell nearest its centroid (the
    first in row order on a tie), so that every uncovered cell has an objective on its own side of the
    walls. Returns the new labels."""
    reached = labels.copy()
    while (eroded & (reached == 0)).any():  # a label, once given, stays: stop when every eroded cell has one
        grown = ndimage.grey_dilation(reached, footprint=np.ones((3, 3), dtype=bool))
        front = uncovered & (reached == 0) & (grown > 0)
        if not front.any():
            break
        reached[front] = grown[front]
    labels = np.where(eroded, reached, labels)
    alone = eroded & (labels == 0)
    count, regions = cv2.connectedComponents(alone.astype(np.uint8), connectivity=8)
    for k in range(1, count):
        rows, cols = np.nonzero(regions == k)
        nearest = int(np.argmin((rows - rows.mean()) ** 2 + (cols - cols.mean()) ** 2))
        labels[rows, cols] = len(positions) + 1
        positions.append(np.array([(cols[nearest] + 0.5) * cell, (rows[nearest] + 0.5) * cell]))
        if cells is not None:
            cells.append((int(rows[nearest]), int(cols[nearest])))
    return labels


def fallback_objective(lack: np.ndarray, agent_positions: np.ndarray, cell: float) -> np.ndarray | None:
    """The uncovered cell centre nearest to any agent, or None if all is covered."""
    rows, cols = np.nonzero(lack > 0.0)
    if rows.size == 0:
        return None
    centres = np.stack([(cols + 0.5) * cell, (rows + 0.5) * cell], axis=1)
    gaps = np.linalg.norm(centres[:, None, :] - agent_positions[None, :, :], axis=2).min(axis=1)
    return centres[int(np.argmin(gaps))]
