import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from model.paper.assignment import assign_objectives, normalised_distances

points = st.lists(st.tuples(st.floats(0, 100), st.floats(0, 100)), min_size=1, max_size=30)


@given(points, points)
def test_each_objective_gets_between_floor_and_ceil_of_n_over_m_agents(agents, objectives):
    agents, objectives = np.array(agents), np.array(objectives)
    choice = assign_objectives(agents, objectives)
    assert choice.shape == (len(agents),)
    assert ((choice >= 0) & (choice < len(objectives))).all()
    counts = np.bincount(choice, minlength=len(objectives))
    n, m = len(agents), len(objectives)
    if n >= m:
        assert counts.min() >= n // m
    assert counts.max() <= -(-n // m)


@given(points, points)
def test_normalised_distances_lie_in_unit_interval(agents, objectives):
    matrix = normalised_distances(np.array(agents), np.array(objectives))
    assert (matrix >= 0).all() and (matrix <= 1 + 1e-12).all()


def test_nearest_agent_takes_each_objective():
    agents = np.array([[0.0, 0.0], [100.0, 0.0]])
    objectives = np.array([[90.0, 0.0], [5.0, 0.0]])
    assert list(assign_objectives(agents, objectives)) == [1, 0]


def test_one_objective_takes_the_whole_team():
    agents = np.array([[0.0, 0.0], [10.0, 0.0], [20.0, 0.0]])
    assert list(assign_objectives(agents, np.array([[5.0, 5.0]]))) == [0, 0, 0]


def test_geodesic_distances_replace_straight_ones_and_unreachable_counts_as_farthest():
    agents = np.array([[0.0, 0.0], [10.0, 0.0]])
    objectives = np.array([[1.0, 0.0], [9.0, 0.0]])
    assert assign_objectives(agents, objectives).tolist() == [0, 1]
    around_a_wall = np.array([[50.0, 2.0], [1.0, 60.0]])  # agent 0 is far from ψ_0 by the free path
    assert assign_objectives(agents, objectives, around_a_wall).tolist() == [1, 0]
    cut_off = np.array([[np.inf, 3.0], [4.0, np.inf]])
    assert assign_objectives(agents, objectives, cut_off).tolist() == [1, 0]


def test_the_straight_normalisation_is_unchanged_by_the_geodesic_option():
    rng = np.random.default_rng(0)
    agents, objectives = rng.uniform(0, 100, (7, 2)), rng.uniform(0, 100, (3, 2))
    straight = np.linalg.norm(agents[:, None, :] - objectives[None, :, :], axis=2)
    assert np.array_equal(normalised_distances(agents, objectives), straight / straight.max())
    assert assign_objectives(agents, objectives).tolist() == assign_objectives(agents, objectives, straight).tolist()
