"""model.controllers.algorithms: the planning step the engine and the coordinator share (Algorithm 1 then 2)."""

from __future__ import annotations

import numpy as np

from model.controllers.algorithms import Planner
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
