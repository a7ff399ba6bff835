"""model.parameters: the law's parameters and the initial poses, in the open and on a terrain."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model.parameters import coverage_map_of, free_initial_poses, initial_poses
from model.scenario import Scenario
from model.scenario.terrain import load_occupancy_map, map_on_grid
from model.world.clearance import disk_is_free
from model.world.world import world_of
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


ISSUE_NOISE = {
    "odometry_per_metre": 0.01, "odometry_per_radian": 0.01, "localiser_sigma": 0.05, "localiser_heading_deg": 2.0,
    "localiser_rate": 10.0, "localiser_latency": 0.1, "command_latency": 0.1,
}  # fmt: skip


def test_a_noisy_team_does_not_ask_the_lab_s_cell_seen_through_a_gap_and_the_truth_still_counts_it():
    """MRPT's lab (a public SLAM map): cell (40, 53) is seen from its only seer's centre and not from 2 belief-σ
    (0.018 m) off it (issue 37: a cleanup that stood 0.027 m off took nothing, and the watchdog gave the cell up).
    ``unsure_sigmas = 0`` asks it again."""
    from model.scenario import load_scenario
    from tests.test_real_maps import REAL, map_of

    map_of(REAL / "uwb-lab.toml")
    lab = load_scenario(REAL / "uwb-lab.toml").with_overrides(physics="mujoco", noise=ISSUE_NOISE)
    team, truth = coverage_map_of(lab), coverage_map_of(lab, with_margin=False)
    assert team.coverage[40, 53] == team.target_ticks and truth.coverage[40, 53] == 0
    assert truth.counted_cells - team.counted_cells == int(world_of(lab).unsure.sum()) <= 5
    asked = lab.with_overrides(noise={**ISSUE_NOISE, "unsure_sigmas": 0.0})
    assert coverage_map_of(asked).coverage[40, 53] == 0 and world_of(lab).summary()["unsure_cells"] >= 1
    exact = lab.with_overrides(noise={})  # without noise every coverable cell is asked
    assert coverage_map_of(exact).coverage[40, 53] == 0 and not world_of(exact).unsure.any()
