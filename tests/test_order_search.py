"""model.controllers.anicov.order_search: the local search over the order in which robots take the spiral's
pieces: its neighbours, its result against every order of five, and its round's shortcuts against the
definition (every neighbour's finish bisected)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from model.controllers.anicov.order_search import improved_order, neighbours
from model.controllers.anicov.piece_order import Spiral, order_finishes
from model.controllers.anicov.routes import CENTRE_ALLOWANCE_LEADS, SEAM_OVERLAP, balanced_routes_on
from tests.test_piece_order import LEAD, PAPER, _spiral


def test_the_neighbours_are_every_swap_and_every_move_once():
    order = np.arange(6)
    around = neighbours(order)
    assert all(sorted(o) == list(range(6)) for o in around)
    assert len({tuple(o) for o in around}) == len(around) == 15 + 6 * 6 - 6 - 2 * 5  # swaps, then moves by 2+
    assert [1, 0, 2, 3, 4, 5] in around.tolist() and [1, 2, 3, 0, 4, 5] in around.tolist()


def test_the_improved_order_finds_the_best_of_all_orders_of_five_and_is_never_later_than_where_it_began():
    _, cut_on = _spiral()
    positions = np.random.default_rng(2).uniform(0.0, 100.0, (5, 2))
    every = np.array(list(itertools.permutations(range(5))))
    finishes = order_finishes(every, positions, cut_on)
    worst = every[int(np.argmax(finishes))]
    order, finish = improved_order(worst, positions, cut_on)
    assert finish == pytest.approx(finishes.min(), abs=1e-6) and finishes.min() < finishes.max() - 40.0
    assert finish == pytest.approx(float(order_finishes(order[None, :], positions, cut_on)[0]))
    # From the resized pieces' own order (model.controllers.anicov.routes), never later than they were estimated.
    scenario = PAPER.with_overrides(agents=8, seed=5)
    positions = np.random.default_rng(5).uniform(0.0, 100.0, (8, 2))
    _, resized, owners = balanced_routes_on(scenario, cut_on.points, positions, LEAD)
    assert improved_order(np.array(owners), positions, cut_on)[1] <= resized + 1e-6


def _steepest_descent_by_definition(
    order: np.ndarray, positions: np.ndarray, cut_on: Spiral
) -> tuple[np.ndarray, float]:
    """improved_order as its docstring defines it: every neighbour's rough finish bisected, the first least
    taken while it is sooner."""
    best = float(order_finishes(order[None, :], positions, cut_on)[0])
    while True:
        around = neighbours(order)
        rough = order_finishes(around, positions, cut_on, below=np.full(len(around), best))
        k = int(np.argmin(rough))
        exact = float(order_finishes(around[k : k + 1], positions, cut_on)[0])
        if rough[k] >= best - 1e-9 or exact >= best - 1e-9:
            return order, best
        order, best = around[k], exact


@pytest.mark.parametrize("seed", range(6))
def test_the_improved_order_is_the_steepest_descent_over_every_neighbours_bisected_finish(seed):
    # improved_order walks each neighbour at one T and bisects only those that reach the end there, from the
    # first place it changes: the same orders, to the bit, as bisecting all of them.
    whole, _ = _spiral()
    cut_on = Spiral(whole.points, whole.along, LEAD, CENTRE_ALLOWANCE_LEADS * LEAD, SEAM_OVERLAP)
    rng = np.random.default_rng(seed)
    agents = int(rng.integers(3, 16))
    positions = rng.uniform(-10.0, 110.0, (agents, 2))
    start = rng.permutation(agents)
    order, finish = improved_order(start, positions, cut_on)
    expected_order, expected_finish = _steepest_descent_by_definition(start, positions, cut_on)
    assert order.tolist() == expected_order.tolist() and finish == expected_finish
    assert finish < float(order_finishes(start[None, :], positions, cut_on)[0])  # it did improve


def test_a_neighbour_reaching_only_at_the_rounds_last_midpoint_is_not_screened_out_by_a_rounding():
    # Found in review: reaching is monotone in the cut only in exact arithmetic; screened at the midpoint itself,
    # the neighbour [2, 1, 0] fell 2e-13 short of a threshold and the search stopped an order early.
    whole, _ = _spiral()
    cut_on = Spiral(whole.points, whole.along, LEAD, CENTRE_ALLOWANCE_LEADS * LEAD, SEAM_OVERLAP)
    positions = np.array(
        [
            [42.29697808688391, 74.40145841934383],
            [23.25254573107513, 108.81010341776836],
            [34.37588719928026, 81.13119253953674],
        ]
    )
    start = np.array([1, 2, 0])
    order, finish = improved_order(start, positions, cut_on)
    expected_order, expected_finish = _steepest_descent_by_definition(start, positions, cut_on)
    assert order.tolist() == expected_order.tolist() == [2, 1, 0] and finish == expected_finish
