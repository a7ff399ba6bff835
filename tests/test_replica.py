import numpy as np
import pytest

from protocol.messages import MapDelta, Snapshot
from protocol.replica import MapReplica


def delta(agent, seq, value=5, row0=0, col0=0):
    return MapDelta(agent, seq, row0, col0, np.full((2, 2), value, dtype=np.int64))


def test_each_agent_sequence_applies_once():
    replica = MapReplica(4, 4, 1.0, 100.0)
    assert replica.apply(delta(0, 0))
    assert not replica.apply(delta(0, 0))
    assert replica.duplicates == 1
    assert replica.map.coverage[0, 0] == 5
    assert replica.has(0, 0) and not replica.has(0, 1) and not replica.has(1, 0)
    assert replica.has(3, -1)


def test_gaps_are_detected_and_filled_out_of_order():
    replica = MapReplica(4, 4, 1.0, 100.0)
    for seq in (0, 1, 4, 6):
        replica.apply(delta(2, seq))
    assert replica.gaps() == {2: [2, 3, 5]}
    for seq in (5, 3, 2):
        replica.apply(delta(2, seq))
    assert replica.gaps() == {}
    assert replica.applied[2].contiguous == 6


def test_replicas_agree_whatever_the_order_and_snapshot_restores_exactly():
    deltas = [delta(a, s, value=a * 10 + s + 1, row0=s % 3, col0=a % 3) for a in range(3) for s in range(5)]
    first, second = MapReplica(5, 5, 1.0, 100.0), MapReplica(5, 5, 1.0, 100.0)
    for item in deltas:
        first.apply(item)
    for item in reversed(deltas):
        second.apply(item)
    assert np.array_equal(first.map.coverage, second.map.coverage)
    late = MapReplica(5, 5, 1.0, 100.0)
    late.load(first.snapshot())
    for item in deltas:  # replays after a snapshot change nothing
        assert not late.apply(item)
    assert np.array_equal(late.map.coverage, first.map.coverage)
    assert late.map.deficit_ticks == first.map.deficit_ticks
    assert late.map.uncovered_cells == first.map.uncovered_cells


def test_adopt_takes_exactly_the_gone_agents_coverage_from_a_snapshot():
    """A live replica saw agents 0, 1 and 2; agent 2 is gone. A fresh replica that replayed only the
    histories of 0 and 1 adopts agent 2's part of the snapshot and ends equal to the live one."""
    deltas = [delta(a, s, value=1 + a + s, row0=s % 3, col0=a) for a in range(3) for s in range(4)]
    live = MapReplica(4, 4, 1.0, 100.0)
    for d in deltas:
        live.apply(d)
    snapshot = live.snapshot()
    known = [d for d in deltas if d.agent != 2]
    rebuilt = MapReplica(4, 4, 1.0, 100.0)
    for d in known:
        rebuilt.apply(d)
    later = delta(0, 4, value=7)  # the histories hold more than the snapshot: not counted as agent 2's
    rebuilt.apply(later)
    rebuilt.adopt(snapshot, [*known, *known[:3], later], {2})  # duplicates in the known list are harmless
    live.apply(later)
    assert rebuilt.digest() == live.digest()
    assert rebuilt.contiguous() == live.contiguous()
    assert rebuilt.map.domain_error() == live.map.domain_error()
    assert not rebuilt.apply(delta(2, 1))  # agent 2's deltas count as applied


def test_adopt_refuses_a_snapshot_that_claims_deltas_its_map_does_not_hold():
    claims = Snapshot(np.zeros((4, 4), dtype=np.int64), {0: (0, ())}, {})  # says (0, 0) is in, map is empty
    with pytest.raises(ValueError, match="cannot tell whose coverage is whose"):
        MapReplica(4, 4, 1.0, 100.0).adopt(claims, [delta(0, 0)], {1})
