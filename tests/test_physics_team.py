"""model.physics.team: the world, the late commands and the truth's own map (issue 37)."""

from __future__ import annotations

import numpy as np

from model.controllers import law_parameters
from model.parameters import coverage_map_of
from model.physics.team import PhysicalTeam
from model.scenario import validate
from model.step import sense_only
from model.world.world import world_of


def test_the_truth_is_sensed_by_eq_2_itself_whatever_the_team_map_doubts():
    """The sure rule (``sure_sigmas``) shrinks what a robot's own map takes; the truth's camera stands where it
    is, so the truth's map takes eq. 2's ticks from the true pose."""
    scenario = validate({
        "domain": [20.0, 20.0], "cell": 1.0, "range": 5.0, "robot_radius": 0.3, "agents": 1, "physics": "mujoco",
        "noise": {"localiser_sigma": 0.05, "localiser_heading_deg": 2.0, "sure_sigmas": 2.0},
    })  # fmt: skip
    ground = world_of(scenario).ground
    team = PhysicalTeam(scenario, np.array([[10.0, 10.0, 0.3]]), ground)
    law = law_parameters(scenario, coverage_map_of(scenario))
    assert law.position_doubt > 0.0
    x, y, theta = team.truth[0]
    team.move(np.zeros((1, 2)), law, ground)
    exact = law._replace(position_doubt=0.0, heading_doubt=0.0)
    blank = np.zeros_like(team.true_map.coverage)
    row0, col0, ticks = sense_only(blank, x, y, theta, exact, ground, team.truth[:, :2], 0)
    *_, doubted = sense_only(blank, x, y, theta, law, ground, team.truth[:, :2], 0)
    assert doubted.sum() < ticks.sum()  # the team's own map would take less
    window = team.true_map.coverage[row0 : row0 + ticks.shape[0], col0 : col0 + ticks.shape[1]]
    assert np.array_equal(window, ticks) and team.true_map.coverage.sum() == ticks.sum()
