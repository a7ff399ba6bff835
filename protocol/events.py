"""Deltas sent as their cause (issue 13): the pose a step sensed from, from which every replica computes
the cells itself, instead of the cells.

The rule, for a delta of agent a at step k sensed from pose (x, y, θ):

1. Every replica computes the ticks with the integer kernel (:func:`model.radio.exact_coverage.event_ticks`):
   the same integers on every CPU, from the pose's three float64 numbers and the scenario.
2. The sender computed its own ticks with the model's float kernel (:mod:`model.world.wedge`), which may
   round a cell the other way (a few cells per hundred thousand) and, on a terrain, leaves out cells a
   wall or a teammate hides. It lists every cell where the two differ, as (flat index in the kernel's
   window, its ticks); replicas write those over the kernel's. So every replica applies exactly the
   sender's ticks, and a run is the same whichever form its deltas travel in.
3. A delta the kernel cannot describe (a window outside the grid's, no kernel for the scenario) or whose
   list would be longer than half its window travels as cells.

On the wire a delta body holds either ``ticks`` (with ``row0``, ``col0``, ``h``, ``w``) or ``ev`` = [x, y, θ]
and ``fix`` = [index, ticks, index, ticks, ...] (indices increasing).
"""

from __future__ import annotations

import numpy as np

from model.radio.exact_coverage import ExactKernel, event_ticks
from protocol.messages import MapDelta, Pose, SensingEvent


def as_event(delta: MapDelta, pose: Pose, kernel: ExactKernel | None) -> MapDelta:
    """The same delta, set to travel as its sensing event when that describes it exactly and is smaller;
    else ``delta`` itself (cells). Its ticks are re-placed in the kernel's window (the same map change)."""
    if kernel is None or delta.ticks.size == 0:
        return delta
    row0, col0, exact = event_ticks(kernel, *pose)
    height, width = exact.shape
    top, left = delta.row0 - row0, delta.col0 - col0  # the sender's window in the kernel's
    rows = slice(max(top, 0), max(min(top + delta.ticks.shape[0], height), max(top, 0)))
    cols = slice(max(left, 0), max(min(left + delta.ticks.shape[1], width), max(left, 0)))
    inside = delta.ticks[rows.start - top : rows.stop - top, cols.start - left : cols.stop - left]
    if int(inside.sum()) != int(delta.ticks.sum()):  # the sender's ticks reach outside the kernel's window
        return delta
    sent = np.zeros_like(exact)
    sent[rows, cols] = inside
    differ = np.flatnonzero(sent != exact)
    if 2 * differ.size > exact.size:
        return delta
    fixes = tuple((int(index), int(sent.flat[index])) for index in differ)
    return MapDelta(delta.agent, delta.seq, row0, col0, sent, SensingEvent(pose, fixes))


def delta_of_event(agent: int, seq: int, event: SensingEvent, kernel: ExactKernel) -> MapDelta:
    """What a replica applies for an event (the fixes already checked against the window)."""
    row0, col0, ticks = event_ticks(kernel, *event.pose)
    flat = ticks.reshape(-1)
    for index, value in event.fixes:
        flat[index] = value
    return MapDelta(agent, seq, row0, col0, ticks, event)
