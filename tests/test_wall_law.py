"""model.wall_law: the global law among walls when the objective is near: look at what is left, and go
nearer when nothing left is in sight (issue 12's stalls on the field map)."""

from __future__ import annotations

import math

import numpy as np

from model.ground import Ground
from model.wall_law import global_law_among_walls, uncovered_to_look_at

TARGET = 100


def ground_of(occupied: np.ndarray, radius: float = 0.5, occlusion: bool = True) -> Ground:
    return Ground(occupied, ~occupied, radius, radius + 0.05, radius, True, bool(occupied.any()), occlusion, 20)


def one_uncovered_cell(row: int, col: int, shape=(20, 20)) -> np.ndarray:
    coverage = np.full(shape, TARGET, dtype=np.int64)
    coverage[row, col] = 0
    return coverage


def test_a_cell_a_teammate_hides_is_not_looked_at():
    occupied = np.zeros((20, 20), dtype=bool)
    occupied[0, 0] = True  # a terrain, so the law among walls applies
    coverage = one_uncovered_cell(10, 15)
    ground = ground_of(occupied)
    alone = uncovered_to_look_at(coverage, TARGET, ground, np.zeros((0, 2)), 5.5, 10.5, 15.5, 10.5, 20.0, 1.0)
    assert alone == (15.5, 10.5)
    teammate_between = np.array([[10.5, 10.5]])
    hidden = uncovered_to_look_at(coverage, TARGET, ground, teammate_between, 5.5, 10.5, 15.5, 10.5, 20.0, 1.0)
    assert all(math.isnan(value) for value in hidden)
    without_occlusion = ground_of(occupied, occlusion=False)
    seen = uncovered_to_look_at(coverage, TARGET, without_occlusion, teammate_between, 5.5, 10.5, 15.5, 10.5, 20.0, 1.0)
    assert seen == (15.5, 10.5)  # the camera's own rule: no occlusion, nothing hides it


def test_with_nothing_left_in_sight_the_robot_goes_nearer_instead_of_waiting():
    occupied = np.zeros((20, 20), dtype=bool)
    occupied[8:13, 12] = True  # a wall just before the last uncovered cell
    coverage = one_uncovered_cell(10, 13)
    ground = ground_of(occupied)
    objective = (11.5, 12.5)  # within R/2, reachable straight: eq. 10 would back the robot away (u < 0)
    x, y = 9.5, 10.5
    u_glo, theta = global_law_among_walls(
        coverage, TARGET, x, y, *objective, -0.3, 0.0, 20.0, 1.0, False, ground, np.zeros((20, 20)), np.zeros((0, 2))
    )
    assert u_glo == 0.3  # nearer, at eq. 10's speed for this distance
    assert math.isclose(theta, math.atan2(objective[1] - y, objective[0] - x))
    coverage_in_sight = one_uncovered_cell(12, 10)
    u_glo, theta = global_law_among_walls(
        coverage_in_sight, TARGET, x, y, *objective, -0.3, 0.0, 20.0, 1.0, False, ground, np.zeros((20, 20)),
        np.zeros((0, 2)),
    )  # fmt: skip
    assert u_glo == 0.0 and math.isclose(theta, math.atan2(12.5 - y, 10.5 - x))  # stops and looks
