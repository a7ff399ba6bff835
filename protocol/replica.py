"""A replica of the team's coverage map: each (agent, sequence) delta applied exactly once.

Deltas are integer windows, so the map is the same whatever order they
arrive in. Per agent the replica remembers the highest sequence up to which
every delta was applied (``contiguous``) and the ones applied beyond it
(``extras``): anything in between is a gap, a delta known to be missing.
A snapshot carries the map with that bookkeeping, so a late or restarted
process can load it and keep applying deltas without double counting.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

import numpy as np

from model.paper.coverage_map import CoverageMap
from model.parameters import coverage_map_of
from model.scenario import Scenario
from protocol.messages import MapDelta, Snapshot


@dataclass
class AppliedSequences:
    contiguous: int = -1
    extras: set[int] = field(default_factory=set)

    def contains(self, seq: int) -> bool:
        return seq <= self.contiguous or seq in self.extras

    def add(self, seq: int) -> None:
        self.extras.add(seq)
        while self.contiguous + 1 in self.extras:
            self.contiguous += 1
            self.extras.discard(self.contiguous)

    def gaps(self) -> list[int]:
        if not self.extras:
            return []
        return [seq for seq in range(self.contiguous + 1, max(self.extras)) if seq not in self.extras]


class MapReplica:
    """A CoverageMap plus exactly-once bookkeeping of who contributed what."""

    def __init__(self, rows: int, cols: int, cell: float, coverage_target: float) -> None:
        self.map = CoverageMap(rows, cols, cell, coverage_target)
        self.applied: dict[int, AppliedSequences] = {}
        self.duplicates = 0
        # A snapshot may be served from Zenoh's thread while the main thread applies deltas.
        self._lock = threading.Lock()

    @classmethod
    def of(cls, scenario: Scenario) -> MapReplica:
        """A fresh replica of a scenario's map (on a terrain, started as its world says)."""
        replica = cls(*scenario.grid_shape, scenario.cell, scenario.lambda_star)
        replica.map = coverage_map_of(scenario)
        return replica

    def has(self, agent: int, seq: int) -> bool:
        """Whether (agent, seq) is in the map; every agent trivially has 'step −1' (nothing)."""
        if seq < 0:
            return True
        sequences = self.applied.get(agent)
        return sequences is not None and sequences.contains(seq)

    def apply(self, delta: MapDelta) -> bool:
        """Add a delta unless this (agent, seq) was applied before; True if it was new."""
        with self._lock:
            sequences = self.applied.setdefault(delta.agent, AppliedSequences())
            if sequences.contains(delta.seq):
                self.duplicates += 1
                return False
            self.map.add(delta.row0, delta.col0, delta.ticks)
            sequences.add(delta.seq)
            return True

    def skip(self, agent: int, upto: int) -> None:
        """Sequences of ``agent`` up to ``upto`` will never come: it was away, and a lockstep team
        readmits it at step ``upto`` + 1. Bookkeeping only: the map is untouched."""
        with self._lock:
            sequences = self.applied.setdefault(agent, AppliedSequences())
            if upto > sequences.contiguous:
                sequences.extras = {seq for seq in sequences.extras if seq > upto}
                sequences.contiguous = upto - 1
                sequences.add(upto)  # merges the extras that follow

    def gaps(self) -> dict[int, list[int]]:
        """Known-missing sequences per agent (a later one arrived, these did not)."""
        return {agent: missing for agent, seqs in self.applied.items() if (missing := seqs.gaps())}

    def contiguous(self) -> dict[str, int]:
        """Per agent (as a JSON key), the sequence up to which every delta of it is in the map."""
        return {str(agent): sequences.contiguous for agent, sequences in sorted(self.applied.items())}

    def snapshot(self, poses: dict[int, tuple[float, float, float]] | None = None) -> Snapshot:
        with self._lock:
            applied = {agent: (seqs.contiguous, tuple(sorted(seqs.extras))) for agent, seqs in self.applied.items()}
            return Snapshot(self.map.coverage.copy(), applied, dict(poses or {}))

    def counts(self) -> dict[str, object]:
        """What a process reports of its replica at the end of a run (tests compare them across processes)."""
        missing = self.gaps()
        return {
            "map_digest": self.digest(),
            "duplicates": self.duplicates,
            "applied": self.contiguous(),
            "gaps": sum(len(seqs) for seqs in missing.values()),
            "missing": {str(agent): seqs for agent, seqs in missing.items()},  # known lost by everyone
        }

    def digest(self) -> str:
        """A short hash of the map, to compare replicas across processes."""
        import hashlib

        return hashlib.sha256(self.map.coverage.tobytes()).hexdigest()[:16]

    def load(self, snapshot: Snapshot) -> None:
        """Replace this replica's content by a snapshot (of the same grid)."""
        if snapshot.coverage.shape != self.map.coverage.shape:
            raise ValueError("snapshot grid differs from this replica's")
        target = self.map.target_ticks
        with self._lock:
            self.map.coverage[...] = snapshot.coverage
            self.map.uncovered_cells = int((snapshot.coverage < target).sum())
            self.map.deficit_ticks = int(np.maximum(target - snapshot.coverage, 0).sum())
            self.applied = {
                agent: AppliedSequences(seq, set(extras)) for agent, (seq, extras) in snapshot.applied.items()
            }

    def adopt(self, snapshot: Snapshot, known: list[MapDelta], agents: set[int]) -> None:
        """Take ``agents``' coverage from another replica's snapshot, exactly.

        ``known`` must hold every delta in the snapshot from any other agent:
        the cells are plain sums, so the snapshot minus those is what ``agents``
        contributed. A restarted coordinator uses it for robots that died
        before it started: their histories are gone, their coverage is not.
        """
        others = np.zeros_like(snapshot.coverage)
        counted: set[tuple[int, int]] = set()
        for delta in known:
            contiguous, extras = snapshot.applied.get(delta.agent, (-1, ()))
            if (delta.agent, delta.seq) in counted or delta.agent in agents:
                continue
            counted.add((delta.agent, delta.seq))
            if delta.seq <= contiguous or delta.seq in extras:
                others[
                    delta.row0 : delta.row0 + delta.ticks.shape[0], delta.col0 : delta.col0 + delta.ticks.shape[1]
                ] += delta.ticks
        theirs = snapshot.coverage - others
        if (theirs < 0).any():
            raise ValueError("the known deltas are not all in the snapshot: cannot tell whose coverage is whose")
        with self._lock:
            for agent in agents:
                if agent in snapshot.applied and agent not in self.applied:
                    seq, extras = snapshot.applied[agent]
                    self.applied[agent] = AppliedSequences(seq, set(extras))
            self.map.add(0, 0, theirs)
