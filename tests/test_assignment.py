import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from model.assignment import assign_objectives, normalised_distances

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
