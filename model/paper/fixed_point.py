"""Fixed-point coverage units shared by every replica of the map.

Coverage Λ (eq. 3) is a sum of contributions. Stored as integers, the sum
commutes exactly, so two replicas that applied the same deltas in any order
are bit-identical. One unit of coverage is ``COVERAGE_SCALE`` integer ticks
(a power of two, so converting back to float is exact).
"""

from __future__ import annotations

COVERAGE_SCALE: int = 1 << 20
"""Integer ticks per unit of coverage Λ (resolution ≈ 1e-6)."""


def coverage_to_ticks(value: float) -> int:
    """Round a coverage amount to the nearest integer number of ticks."""
    return int(value * COVERAGE_SCALE + 0.5)
