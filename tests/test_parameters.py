"""model.parameters: the law's parameters and the initial poses, in the open and on a terrain."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model.parameters import free_initial_poses, initial_poses
from model.scenario import Scenario
from model.scenario.terrain import load_occupancy_map, map_on_grid
from model.world.clearance import disk_is_free
from tests.conftest import ROOT


def test_the_papers_initial_poses_are_uniform_in_the_domain_from_the_seed():
    poses = initial_poses(Scenario(agents=30, seed=5))
    assert poses.shape == (30, 3)
    assert np.array_equal(poses, initial_poses(Scenario(agents=30, seed=5)))
    assert (poses[:, :2] >= 0).all() and (poses[:, :2] <= 100).all() and (np.abs(poses[:, 2]) <= math.pi).all()


def test_on_a_map_every_robot_starts_free_of_walls_and_of_its_teammates():
    occupied = map_on_grid(load_occupancy_map(ROOT / "scenarios" / "maps" / "warehouse.yaml"), 1.0)
    poses = free_initial_poses(occupied, 1.0, agents=10, seed=3, radius=0.5, clearance=0.2)
    assert np.array_equal(poses, free_initial_poses(occupied, 1.0, agents=10, seed=3, radius=0.5, clearance=0.2))
    for i, (x, y, _) in enumerate(poses):
        assert disk_is_free(occupied, x, y, 0.7, 1.0, True)
        for px, py, _ in poses[:i]:
            assert math.hypot(x - px, y - py) >= 1.2


def test_a_team_too_big_for_its_free_space_is_refused():
    occupied = np.ones((10, 10), dtype=bool)
    occupied[4:6, 4:6] = False  # a 2 x 2 pocket holds one robot of radius 0.5, not two
    assert free_initial_poses(occupied, 1.0, agents=1, seed=0, radius=0.5, clearance=0.2).shape == (1, 3)
    with pytest.raises(ValueError, match=r"cannot hold 2 robots of radius 0\.5"):
        free_initial_poses(occupied, 1.0, agents=2, seed=0, radius=0.5, clearance=0.2)
