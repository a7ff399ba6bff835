"""Section V's reference numbers, which follow from eq. 2 alone (DESIGN.md §4)."""

import math

import pytest

from model.paper.metrics import (
    coverage_distance,
    optimum_time,
    pass_reach,
    straight_pass_coverage,
    total_sensing_ability,
)
from model.scenario import Scenario

R, ALPHA = 20.0, 50.0
F = math.radians(27.0)


def test_total_ability_eq18_matches_closed_form_and_paper():
    ability = total_sensing_ability(R, F, ALPHA)
    assert ability == pytest.approx(ALPHA * R * R * F / 6.0, rel=1e-9)
    assert ability == pytest.approx(1570.8, rel=0.005)


def test_optimum_time_eq19():
    assert optimum_time(1e4, 100.0, 1570.8, 4) == pytest.approx(159.15, abs=0.01)


def test_d100_and_d50_match_paper_with_half_angle_27_degrees():
    assert coverage_distance(100.0, R, F, ALPHA) == pytest.approx(2.72, rel=0.01)
    assert coverage_distance(50.0, R, F, ALPHA) == pytest.approx(3.865, rel=0.01)


def test_a_scenarios_pass_reach_is_its_sensors_d100_and_d50():
    paper = Scenario()
    assert pass_reach(paper) == coverage_distance(paper.lambda_star, paper.range, paper.half_angle, paper.alpha_max)
    assert pass_reach(paper, 0.5) == pytest.approx(3.865, rel=0.01)
    assert pass_reach(paper.with_overrides(range=10.0)) < pass_reach(paper)


def test_half_angle_54_degrees_does_not_match_paper():
    """Reading 1: the printed F = 54° gives d100 ≈ 5.50, twice the paper's figure."""
    assert coverage_distance(100.0, R, math.radians(54.0), ALPHA) == pytest.approx(5.50, abs=0.01)


def test_straight_pass_profile_decreases_with_offset():
    values = [straight_pass_coverage(d, R, F, ALPHA) for d in (0.0, 1.0, 3.0, 6.0, 9.0)]
    assert values == sorted(values, reverse=True)
    assert straight_pass_coverage(R * math.sin(F) + 0.1, R, F, ALPHA) == 0.0
