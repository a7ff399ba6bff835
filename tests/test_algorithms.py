"""model.controllers.algorithms: the planning step the engine and the coordinator share (Algorithm 1 then 2)."""

from __future__ import annotations

import numpy as np

from model.controllers.algorithms import COMMITMENT, Planner, blob_targets, held_to_their_places
from model.paper.objectives import BlobObjectives
from model.scenario import Scenario

SCENARIO = Scenario(domain=(60.0, 60.0), agents=3)


def test_every_agent_gets_one_of_the_blob_objectives_and_the_blobs_are_remembered():
    planner = Planner(SCENARIO)
    lack = np.zeros(SCENARIO.grid_shape)
    lack[5:20, 5:20] = 1.0  # two uncovered squares far apart: two blobs, two objectives
    lack[40:55, 40:55] = 1.0
    positions = np.array([[5.0, 5.0], [55.0, 5.0], [30.0, 55.0]])
    targets = planner.plan(lack, positions)
    assert targets.shape == (3, 2)
    objectives = {tuple(point) for point in planner.blobs.positions}
    assert len(objectives) == 2 and all(tuple(target) in objectives for target in targets)
    assert len({tuple(target) for target in targets}) == 2  # Alg. 2 spreads three agents over both
    labels = planner.labels()
    assert labels is not None and labels.dtype == np.uint16 and labels.shape == SCENARIO.grid_shape
    step, members, kept, blobs, kept_labels = planner.record(10, targets)
    assert (step, members) == (10, (0, 1, 2)) and np.array_equal(kept, targets)
    assert np.array_equal(blobs, planner.blobs.positions) and np.array_equal(kept_labels, labels)


def test_a_fully_covered_map_sends_everyone_nowhere():
    planner = Planner(SCENARIO)
    positions = np.array([[5.0, 5.0], [55.0, 5.0], [30.0, 55.0]])
    assert np.array_equal(planner.plan(np.zeros(SCENARIO.grid_shape), positions), positions)


def test_a_blob_is_seen_for_an_uncovered_cell_of_its_own():
    """blob_targets: the cell Algorithm 1 found the objective in while it is uncovered; covered, the cell its
    point falls in (a centroid on a cell's edge falls in the next cell: lines 1-5 keep the objective for
    that one); both covered, the blob's uncovered cell nearest the point (the first in row order on a tie)."""
    lack = np.zeros((10, 10))
    labels = np.zeros((10, 10), dtype=np.int32)
    labels[4:8, 5] = 1  # a blob of four cells in a column
    lack[4:8, 5] = 1.0
    point = np.array([5.5, 6.0])  # on the edge between rows 5 and 6 (cell 1.0): it falls in row 6
    blobs = BlobObjectives(positions=point[None, :], labels=labels, cells=np.array([[5, 5]]))
    assert blob_targets(blobs, lack, 1.0).tolist() == [[5.5, 5.5]]
    lack[5, 5] = 0.0
    assert blob_targets(blobs, lack, 1.0).tolist() == [[5.5, 6.5]]
    lack[6, 5] = 0.0
    assert blob_targets(blobs, lack, 1.0).tolist() == [[5.5, 4.5]]  # rows 4 and 7 left, as near: the first


def test_algorithm_2_keeps_each_robot_on_its_place_unless_another_is_much_nearer():
    """Two robots, three places in a row 1 apart, cells of 0.5: robot 0 at 0.6, sent to place 0 last plan, robot 1 at
    1.45, sent to place 1; both now nearer place 1 than to any other. On the bare lengths greedy Algorithm 2 gives
    place 1 to the nearer, robot 0, and robot 1 turns to place 2: as they drive the two swap every plan. Held to
    the places they were sent to, each keeps its own while no other is COMMITMENT cells nearer."""
    from model.paper.assignment import assign_objectives

    places = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    positions = np.array([[0.6, 0.0], [1.45, 0.0]])
    lengths = np.abs(positions[:, None, 0] - places[None, :, 0])
    assert list(assign_objectives(positions, places, lengths)) == [1, 2]  # the nearer: 0.4 against 0.45
    held = held_to_their_places(lengths, places, [(0.0, 0.0), (1.0, 0.0)], cell=0.5)
    assert list(assign_objectives(positions, places, held)) == [0, 1]  # each keeps the place it was sent to
    assert held[0, 0] == max(0.6 - COMMITMENT * 0.5, 0.0) and held[0, 1] == lengths[0, 1]
    gone = held_to_their_places(lengths, places, [(0.0, 0.5), None], cell=0.5)
    assert np.array_equal(gone, lengths)  # a place no longer an objective, or none: nothing held
