import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from model.paper.fixed_point import COVERAGE_SCALE
from model.paper.metrics import total_sensing_ability
from model.paper.sensing import lack_of_coverage, sensing_ability, sure_sensing_ability
from model.world.ground import NO_POSITIONS, Ground, open_ground
from model.world.wedge import sense_wedge

OPEN = (open_ground(), NO_POSITIONS, 0)  # the paper's open world: nothing hides anything

R, F, ALPHA = 20.0, math.radians(27.0), 50.0
TARGET = 100 * COVERAGE_SCALE


def test_sensing_ability_is_maximal_at_apex_and_zero_on_the_border():
    assert sensing_ability(0.0, 0.0, R, F, ALPHA) == ALPHA
    assert sensing_ability(R, 0.0, R, F, ALPHA) == 0.0
    assert sensing_ability(0.0, F, R, F, ALPHA) == 0.0
    assert sensing_ability(R + 0.1, 0.0, R, F, ALPHA) == 0.0
    assert sensing_ability(1.0, F + 0.01, R, F, ALPHA) == 0.0


@given(st.floats(0.0, 30.0), st.floats(0.0, math.pi))
def test_sensing_ability_matches_eq2_and_is_bounded(r, offset):
    value = sensing_ability(r, offset, R, F, ALPHA)
    assert 0.0 <= value <= ALPHA
    if r <= R and offset <= F:
        assert value == pytest.approx(ALPHA * (R - r) * (F - offset) / (R * F))
    else:
        assert value == 0.0


@given(st.floats(0.0, 30.0), st.floats(0.0, math.pi), st.floats(0.0, 1.0), st.floats(0.0, 0.1))
@settings(max_examples=300)
def test_a_sure_point_lies_in_the_wedge_from_every_pose_within_the_doubt(r, offset, position_doubt, heading_doubt):
    """Issue 37, item 4: where the sure ability is not 0, the point is in the wedge from every pose within the
    doubt (poses on the doubt's rim, where it is tightest, every 15°), and there it is eq. 2 itself."""
    sure = sure_sensing_ability(r, offset, R, F, ALPHA, (position_doubt, heading_doubt))
    assert sure in (0.0, sensing_ability(r, offset, R, F, ALPHA))
    if sure == 0.0:
        return
    point = np.array([r * math.cos(offset), r * math.sin(offset)])  # the believed pose at the origin, facing +x
    for way in np.radians(np.arange(0.0, 360.0, 15.0)):
        at = position_doubt * np.array([math.cos(way), math.sin(way)])
        for turn in (-heading_doubt, heading_doubt):
            seen = point - at
            distance = float(np.hypot(*seen))
            bearing = abs(math.remainder(math.atan2(seen[1], seen[0]) - turn, 2.0 * math.pi))
            assert distance <= R + 1e-9
            assert bearing <= F + 1e-9


def test_the_wedge_is_shrunk_by_the_doubt_at_its_edges_only():
    assert sure_sensing_ability(10.0, 0.1, R, F, ALPHA, (0.0, 0.0)) == sensing_ability(10.0, 0.1, R, F, ALPHA)
    assert sure_sensing_ability(10.0, 0.1, R, F, ALPHA, (0.1, 0.03)) == sensing_ability(10.0, 0.1, R, F, ALPHA)
    assert sure_sensing_ability(10.0, F - 0.02, R, F, ALPHA, (0.0, 0.03)) == 0.0  # the heading may put it outside
    assert sure_sensing_ability(10.0, F - 0.02, R, F, ALPHA, (0.3, 0.0)) == 0.0  # asin(0.3 / 10) > 0.02
    assert sure_sensing_ability(R - 0.05, 0.0, R, F, ALPHA, (0.1, 0.0)) == 0.0  # it may lie out of reach
    assert sure_sensing_ability(0.05, 0.0, R, F, ALPHA, (0.1, 0.0)) == 0.0  # the robot may stand on it


def test_a_doubted_pass_adds_a_subset_of_the_exact_ticks_and_nearly_all_of_them():
    """The sure ticks are the exact ones on the shrunk wedge and 0 at its edges; with σ-sized doubts (0.05 and
    2°, on R = 20 and F = 27°) they keep nearly all of the wedge's coverage."""
    coverage = np.zeros((100, 100), dtype=np.int64)
    *_, exact = sense_wedge(coverage, TARGET, 50.3, 50.6, 0.4, R, F, ALPHA, 0.1, 1.0, *OPEN)
    *_, sure = sense_wedge(coverage, TARGET, 50.3, 50.6, 0.4, R, F, ALPHA, 0.1, 1.0, *OPEN, (0.05, math.radians(2)))
    kept = sure > 0
    assert (sure[kept] == exact[kept]).all()
    assert 0 < kept.sum() < (exact > 0).sum()
    assert 0.97 < sure.sum() / exact.sum() < 1.0


def test_lack_of_coverage_eq4():
    assert lack_of_coverage(0, TARGET) == 1.0
    assert lack_of_coverage(TARGET // 4, TARGET) == 0.75
    assert lack_of_coverage(TARGET, TARGET) == 0.0
    assert lack_of_coverage(3 * TARGET, TARGET) == 0.0


@pytest.mark.parametrize("cell", [1.0, 0.5, 0.25])
@pytest.mark.parametrize("theta", [0.0, 0.7, -2.5])
def test_delta_integrates_to_total_ability_times_dt(cell, theta):
    """Σ cells of α·dt over the wedge → 𝒜·dt (eq. 18) as the grid is refined."""
    cells = int(100 / cell)
    coverage = np.zeros((cells, cells), dtype=np.int64)
    dt = 0.1
    *_, ticks = sense_wedge(coverage, TARGET, 50.0, 50.0, theta, R, F, ALPHA, dt, cell, *OPEN)
    integral = ticks.sum() / COVERAGE_SCALE * cell * cell
    exact = total_sensing_ability(R, F, ALPHA) * dt
    assert integral == pytest.approx(exact, rel=0.02 if cell == 1.0 else 0.006)


def test_fresh_map_reads_full_error_and_balanced_gradient_when_heading_along_axis():
    coverage = np.zeros((100, 100), dtype=np.int64)
    e_omega, w_left, w_right, *_ = sense_wedge(coverage, TARGET, 50.5, 50.5, 0.0, R, F, ALPHA, 0.1, 1.0, *OPEN)
    assert e_omega == 1.0
    assert w_left == pytest.approx(w_right)
    assert w_left > 0.0


def test_covered_left_half_pulls_gradient_right():
    coverage = np.zeros((100, 100), dtype=np.int64)
    coverage[51:, :] = TARGET  # rows above the agent (left when heading +x) are covered
    e_omega, w_left, w_right, *_ = sense_wedge(coverage, TARGET, 50.5, 50.5, 0.0, R, F, ALPHA, 0.1, 1.0, *OPEN)
    assert w_left == 0.0 and w_right > 0.0
    assert 0.4 < e_omega < 0.6


def test_wedge_outside_domain_counts_area_but_no_error():
    coverage = np.zeros((100, 100), dtype=np.int64)
    e_omega, w_left, w_right, _row0, _col0, ticks = sense_wedge(
        coverage, TARGET, 100.0, 50.5, 0.0, R, F, ALPHA, 0.1, 1.0, *OPEN
    )
    assert e_omega == 0.0 and w_left == 0.0 and w_right == 0.0
    assert ticks.size == 0 or ticks.sum() == 0


@settings(max_examples=60)
@given(st.floats(-30.0, 130.0), st.floats(-30.0, 130.0), st.floats(-math.pi, math.pi))
def test_delta_window_lies_inside_grid_and_is_non_negative(x, y, theta):
    coverage = np.zeros((100, 100), dtype=np.int64)
    e_omega, w_left, w_right, row0, col0, ticks = sense_wedge(
        coverage, TARGET, x, y, theta, R, F, ALPHA, 0.1, 1.0, *OPEN
    )
    assert 0.0 <= e_omega <= 1.0
    assert w_left >= 0.0 and w_right >= 0.0
    assert (ticks >= 0).all()
    if ticks.size:
        assert row0 >= 0 and col0 >= 0
        assert row0 + ticks.shape[0] <= 100 and col0 + ticks.shape[1] <= 100


def _ground(occupied: np.ndarray, radius: float = 0.0, occlusion: bool = True) -> Ground:
    return Ground(
        occupied, ~occupied, radius, radius, radius, False, bool(occupied.any()), occlusion, 20, occupied, 1.0
    )


def _ticks_at(window: tuple, row: int, col: int) -> int:
    _, _, _, row0, col0, ticks = window
    inside = 0 <= row - row0 < ticks.shape[0] and 0 <= col - col0 < ticks.shape[1]
    return int(ticks[row - row0, col - col0]) if inside else 0


def test_a_camera_does_not_see_through_a_wall():
    coverage = np.zeros((40, 40), dtype=np.int64)
    wall = np.zeros((40, 40), dtype=bool)
    wall[15:25, 15] = True  # a wall across the view, 5 cells ahead
    pose = (10.5, 20.5, 0.0)
    behind, beside = (20, 20), (20, 12)  # row, col: 10 cells ahead behind the wall; 2 cells ahead before it
    open_view = sense_wedge(
        coverage, TARGET, *pose, R, F, ALPHA, 0.1, 1.0, _ground(np.zeros_like(wall)), NO_POSITIONS, 0
    )
    walled = sense_wedge(coverage, TARGET, *pose, R, F, ALPHA, 0.1, 1.0, _ground(wall), NO_POSITIONS, 0)
    assert _ticks_at(open_view, *behind) > 0 and _ticks_at(walled, *behind) == 0
    assert _ticks_at(walled, *beside) == _ticks_at(open_view, *beside) > 0
    assert walled[0] < open_view[0]  # hidden cells count in the wedge with nothing to cover there
    unhidden = sense_wedge(
        coverage, TARGET, *pose, R, F, ALPHA, 0.1, 1.0, _ground(wall, occlusion=False), NO_POSITIONS, 0
    )
    assert _ticks_at(unhidden, *behind) == _ticks_at(open_view, *behind)  # occlusion = false: as before


def test_two_robots_hide_each_other():
    coverage = np.zeros((40, 40), dtype=np.int64)
    nothing = np.zeros((40, 40), dtype=bool)
    positions = np.array([[10.5, 20.5], [15.5, 20.5]])  # robot 1 stands 5 units ahead of robot 0
    behind_1, behind_0 = (20, 20), (20, 5)
    first = sense_wedge(coverage, TARGET, 10.5, 20.5, 0.0, R, F, ALPHA, 0.1, 1.0, _ground(nothing, 1.0), positions, 0)
    second = sense_wedge(
        coverage, TARGET, 15.5, 20.5, math.pi, R, F, ALPHA, 0.1, 1.0, _ground(nothing, 1.0), positions, 1
    )
    assert _ticks_at(first, *behind_1) == 0 and _ticks_at(second, *behind_0) == 0
    point_robots = sense_wedge(
        coverage, TARGET, 10.5, 20.5, 0.0, R, F, ALPHA, 0.1, 1.0, _ground(nothing, 0.0), positions, 0
    )
    assert _ticks_at(point_robots, *behind_1) > 0  # r = 0 hides nothing
    assert _ticks_at(first, 20, 13) > 0  # what lies before the teammate is seen
