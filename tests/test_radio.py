"""model.radio.radio: contact, one-hop anti-entropy, local planning's members, divergence."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from model.radio.radio import contacts, divergence, local_members, merge_knowledge


def test_contacts_are_symmetric_reflexive_and_cut_at_the_range():
    positions = np.array([[0.0, 0.0], [3.0, 4.0], [0.0, 5.1], [100.0, 100.0]])
    near = contacts(positions, 5.0)
    assert near.tolist() == [
        [True, True, False, False],
        [True, True, True, False],  # (3, 4) to (0, 5.1): 3.2
        [False, True, True, False],
        [False, False, False, True],
    ]
    assert contacts(positions, math.inf).all()


def test_anti_entropy_moves_one_hop_per_step_along_a_chain():
    """0 - 1 - 2 in a chain: what 0 made reaches 1 at the first exchange and 2 at the second."""
    chain = np.array([[True, True, False], [True, True, True], [False, True, True]])
    knows = np.diag([5, 3, 2])
    once = merge_knowledge(knows, chain)
    assert once.tolist() == [[5, 3, 0], [5, 3, 2], [0, 3, 2]]
    assert merge_knowledge(once, chain).tolist() == [[5, 3, 2], [5, 3, 2], [5, 3, 2]]


@settings(max_examples=200, deadline=None)
@given(st.integers(2, 6), st.integers(0, 2**32 - 1))
def test_knowledge_only_grows_and_never_exceeds_the_maker(agents, seed):
    """Across random contact graphs: a replica never forgets, never knows more of j than j made, and
    once the graph is connected for N − 1 steps everyone knows everything."""
    rng = np.random.default_rng(seed)
    made = np.zeros(agents, dtype=np.int64)
    knows = np.zeros((agents, agents), dtype=np.int64)
    for _ in range(20):
        made += rng.integers(0, 3, agents)
        np.fill_diagonal(knows, made)
        links = rng.random((agents, agents)) < 0.3
        graph = links | links.T | np.eye(agents, dtype=bool)
        learnt = merge_knowledge(knows, graph)
        assert (learnt >= knows).all() and (learnt <= made[None, :]).all()
        knows = learnt
    for _ in range(agents - 1):
        knows = merge_knowledge(knows, np.ones((agents, agents), dtype=bool) & contacts(np.zeros((agents, 2)), 1.0))
    assert (knows == made[None, :]).all()


def test_local_members_are_the_robot_and_those_it_hears_by_id():
    graph = np.array([[True, False, True], [False, True, False], [True, False, True]])
    assert local_members(0, graph) == [0, 2]
    assert local_members(1, graph) == [1]


def test_divergence_counts_cells_whose_lack_of_coverage_differs():
    union = np.array([[100, 250, 0]])
    replicas = [union.copy(), np.array([[100, 120, 0]]), np.array([[40, 90, 0]])]
    # Target 100: 250 and 120 are both covered; 90 is not; 40 is not.
    assert divergence(replicas, union, 100).tolist() == [0, 0, 2]
