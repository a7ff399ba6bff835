"""anicov.radio_engine: one replica per robot, a radio of limited range, central or local planning."""

import math

import numpy as np
import pytest

from anicov.engine import run_scenario
from anicov.radio_engine import run_ranged
from model.parameters import coverage_map_of, starting_poses
from model.scenario import ScenarioError, validate
from runtime.rundir import summary_of
from tests.test_watchdog import stalling_values


@pytest.fixture
def small(paper_scenario):
    """A 40 × 40 square: runs of a second or two; a range of 8 still leaves robots out of touch."""
    return paper_scenario.with_overrides(domain=[40.0, 40.0], agents=4, seed=2)


@pytest.fixture
def rooms(paper_scenario):
    """Two rooms joined by a door (24 × 16), four robots with bodies and the filter, anicov."""
    return paper_scenario.with_overrides(
        domain=[24.0, 16.0], cell=1.0, range=5.0, robot_radius=0.4, occlusion=True, agents=4, seed=2,
        controller="anicov", stations=True,
        obstacles=[[[12.0, 0.0], [13.0, 0.0], [13.0, 6.0], [12.0, 6.0]],
                   [[12.0, 10.0], [13.0, 10.0], [13.0, 16.0], [12.0, 16.0]]],
    )  # fmt: skip


@pytest.mark.parametrize("planning", ["central", "local"])
def test_unlimited_range_equals_the_engine_byte_for_byte(small, planning):
    """Every replica holds every event of step k at step k + 1, and every local planner computes the
    central plan: the run is the paper's, central or local (run_scenario takes the paper's engine for
    central planning with unlimited range: the ranged engine is called here directly)."""
    reference = run_scenario(small)
    scenario = small.with_overrides(planning=planning)
    ranged = run_ranged(scenario, coverage_map_of(scenario), starting_poses(scenario), True, None)
    assert ranged.radio is not None and ranged.radio["divergence_max"] == 0
    assert ranged.trace.tobytes() == reference.trace.tobytes()
    assert ranged.errors.tobytes() == reference.errors.tobytes()
    assert [plan[2].tobytes() for plan in ranged.plans] == [plan[2].tobytes() for plan in reference.plans]


def test_anicov_among_walls_plans_locally_as_centrally_with_an_unlimited_range(rooms):
    """Issue 36, item 3: anicov with robot bodies and the filter, each robot planning on its own replica: with
    every replica whole every robot's planner cuts the team's routes and advances them as the central one."""
    reference = run_scenario(rooms)
    ranged = run_ranged(
        rooms.with_overrides(planning="local"), coverage_map_of(rooms), starting_poses(rooms), True, None
    )
    assert reference.completed and ranged.trace.tobytes() == reference.trace.tobytes()
    assert [plan[2].tobytes() for plan in ranged.plans] == [plan[2].tobytes() for plan in reference.plans]


def test_anicov_among_walls_plans_locally_on_a_limited_range_and_still_covers(rooms):
    result = run_scenario(rooms.with_overrides(comm_range=5.0, planning="local"))
    assert result.completed and result.radio is not None and result.radio["divergence_max"] > 0


@pytest.mark.parametrize("planning", ["central", "local"])
def test_a_limited_range_diverges_replicas_and_still_covers(small, planning):
    scenario = small.with_overrides(comm_range=8.0, planning=planning)
    result = run_scenario(scenario)
    assert result.completed
    radio = result.radio
    assert radio is not None
    assert radio["divergence_max"] > 0 and radio["divergence_mean"] > 0  # replicas did differ
    assert 0.0 <= radio["teammates_heard_mean"] < 3.0  # not everyone heard everyone
    assert run_scenario(scenario).trace.tobytes() == result.trace.tobytes()  # deterministic
    summary = summary_of(result)
    assert summary["scenario"]["comm_range"] == 8.0 and summary["radio"] == radio


def test_local_planning_with_a_limited_range_plans_differently_from_central(small):
    central = run_scenario(small.with_overrides(comm_range=8.0))
    local = run_scenario(small.with_overrides(comm_range=8.0, planning="local"))
    assert central.trace.tobytes() != local.trace.tobytes()


def test_the_paper_summary_has_no_radio_keys(small):
    summary = summary_of(run_scenario(small))
    assert "radio" not in summary and "comm_range" not in summary["scenario"] and "planning" not in summary["scenario"]


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"comm_range": 0.0}, "scenario key 'comm_range': expected a positive number or inf"),
        ({"comm_range": "far"}, "scenario key 'comm_range'"),
        ({"planning": "everywhere"}, "scenario key 'planning': expected one of central, local"),
        (
            {"planning": "local", "controller": "zigzag"},
            "scenario key 'planning': 'local' runs the planner on each robot; controller 'zigzag' plans for the whole team",
        ),
        ({"robot_radius": 0.5, "comm_range": 2.0}, "scenario key 'comm_range': expected at least safety_range"),
    ],
)
def test_bad_radio_keys_name_the_key(small, overrides, message):
    with pytest.raises(ScenarioError, match=message.replace("(", r"\(")):
        small.with_overrides(**overrides)


def test_comm_range_inf_is_the_default(small):
    assert small.comm_range == math.inf and small.with_overrides(comm_range=math.inf) == small
    assert np.isinf(small.with_overrides(comm_range=float("inf")).comm_range)


def crawling_values(**extra):
    """Two robots that barely move (k_v = 1e-4) in tests/test_watchdog.py's open square: they cover what they
    see from their starts and then nothing, so the watchdog sets cells aside and gives them up until none is
    left (every run ends at t = 1800 of max_time 2000; measured)."""
    values = stalling_values(agents=2, initial_poses=[[2.0, 2.0, 0.0], [3.0, 2.0, 90.0]], k_v=1e-4, **extra)
    values.pop("objectives")
    return values


@pytest.mark.parametrize("planning", ["central", "local"])
def test_the_watchdog_ends_a_stalled_run_on_a_radio_as_in_the_engine(planning):
    """On a radio of limited range the central planner's watchdog, or each robot's own (planning locally),
    gives up the cells left and the run ends there, when the engine's does."""
    result = run_scenario(validate(crawling_values(comm_range=8.0, planning=planning)))
    engine = run_scenario(validate(crawling_values()))
    assert not result.completed and result.steps == engine.steps < engine.scenario.max_steps
    left = result.final_lack > 0.0
    assert left.any() and not (left & ~result.given_up).any()
    # Central: the planner's watchdog. Local: each robot's; both in touch, they saw every stall alike,
    # reported once (as the engine's, and the coordinator's over the bus).
    assert [(stall.time, stall.action) for stall in result.stalls] == [(s.time, s.action) for s in engine.stalls]
