import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from model.paper.coverage_map import CoverageMap
from model.paper.fixed_point import COVERAGE_SCALE

window = st.tuples(
    st.integers(0, 7), st.integers(0, 7), st.lists(st.integers(0, 60 * COVERAGE_SCALE), min_size=9, max_size=9)
)


def apply_all(windows, order):
    grid = CoverageMap(10, 10, 1.0, 100.0)
    for index in order:
        row0, col0, values = windows[index]
        grid.add(row0, col0, np.array(values, dtype=np.int64).reshape(3, 3))
    return grid


@settings(max_examples=50)
@given(st.lists(window, min_size=1, max_size=12), st.randoms())
def test_deltas_commute_bit_for_bit_and_bookkeeping_is_exact(windows, rng):
    order = list(range(len(windows)))
    forward = apply_all(windows, order)
    rng.shuffle(order)
    shuffled = apply_all(windows, order)
    assert np.array_equal(forward.coverage, shuffled.coverage)
    target = forward.target_ticks
    assert forward.uncovered_cells == int((forward.coverage < target).sum())
    assert forward.deficit_ticks == int(np.maximum(target - forward.coverage, 0).sum())
    assert forward.domain_error() == pytest.approx(forward.lack_of_coverage().mean(), rel=1e-12)
    assert (forward.uncovered_cells, forward.deficit_ticks) == (shuffled.uncovered_cells, shuffled.deficit_ticks)


def test_fresh_map_has_full_error():
    grid = CoverageMap(4, 5, 1.0, 100.0)
    assert grid.domain_error() == 1.0 and not grid.complete and grid.uncovered_cells == 20
