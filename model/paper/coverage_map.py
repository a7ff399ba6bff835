"""The coverage map Λ (eq. 3) as a grid of fixed-point cells.

Every cell is a grow-only counter of integer ticks (:mod:`model.paper.fixed_point`):
adding deltas commutes exactly, so replicas that applied the same deltas agree
bit for bit whatever the order. The map also keeps, exactly and
incrementally, the number of cells still uncovered and the summed deficit
Σ max(0, Λ* − Λ) from which e_D (eq. 5) follows.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from model.paper.fixed_point import COVERAGE_SCALE


@njit(cache=True)
def add_window(coverage: np.ndarray, row0: int, col0: int, ticks: np.ndarray, target_ticks: int) -> tuple[int, int]:
    """Add a window of ticks to the grid; return (deficit removed, cells newly covered)."""
    height, width = ticks.shape
    deficit_removed = 0
    newly_covered = 0
    for i in range(height):
        for j in range(width):
            added = ticks[i, j]
            if added == 0:
                continue
            before = coverage[row0 + i, col0 + j]
            after = before + added
            coverage[row0 + i, col0 + j] = after
            if before < target_ticks:
                deficit_removed += min(after, target_ticks) - before
                if after >= target_ticks:
                    newly_covered += 1
    return deficit_removed, newly_covered


def load_kernels() -> None:
    """Have numba load this module's compiled kernels now (a quarter of a second from its cache at the
    first call): a process calls it while the team gathers, so that step 0 does not pay for it."""
    scratch = np.zeros((1, 1), dtype=np.int64)
    add_window(scratch, 0, 0, scratch.copy(), 1)


class CoverageMap:
    """Λ over a rectangular domain, in fixed-point ticks, with e_D kept up to date."""

    def __init__(self, rows: int, cols: int, cell: float, coverage_target: float) -> None:
        self.cell = cell
        self.target_ticks = round(coverage_target * COVERAGE_SCALE)
        self.coverage = np.zeros((rows, cols), dtype=np.int64)
        self.uncovered_cells = rows * cols
        self.deficit_ticks = rows * cols * self.target_ticks
        self.counted_cells = rows * cols  # the cells e_D averages over

    def start_from(self, head_start: np.ndarray) -> None:
        """A terrain's start (:meth:`model.world.world.World.head_start`): cells at Λ* are out of e_D and of
        completion; a priority map's cells start part-way. Only for a fresh map."""
        self.coverage[...] = head_start
        self.uncovered_cells = int((head_start < self.target_ticks).sum())
        self.deficit_ticks = int(np.maximum(self.target_ticks - head_start, 0).sum())
        self.counted_cells = self.uncovered_cells  # a fresh map: every cell still to cover counts

    @property
    def shape(self) -> tuple[int, int]:
        return self.coverage.shape  # type: ignore[return-value]

    def add(self, row0: int, col0: int, ticks: np.ndarray) -> None:
        """Apply one delta window (already clipped to the grid)."""
        removed, covered = add_window(self.coverage, row0, col0, ticks, self.target_ticks)
        self.deficit_ticks -= removed
        self.uncovered_cells -= covered

    def lack_of_coverage(self) -> np.ndarray:
        """Υ for every cell, eq. 4."""
        deficit = np.maximum(self.target_ticks - self.coverage, 0)
        return deficit.astype(np.float64) / self.target_ticks

    def domain_error(self) -> float:
        """e_D, eq. 5: mean Υ over the domain (all cells have the same area), coverable cells only."""
        return self.deficit_ticks / (self.target_ticks * self.counted_cells)

    @property
    def complete(self) -> bool:
        return self.uncovered_cells == 0
