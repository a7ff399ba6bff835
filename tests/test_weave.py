"""model.controllers.anicov.weave: the anicov controller's passes, straight or weaving, their coverage profile and rings."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from model.controllers.anicov import lane_planner, weave
from model.controllers.anicov.route import Route
from model.controllers.anicov.routes import CENTRE_ALLOWANCE_LEADS, best_lane_spacing, spiral_in
from model.controllers.anicov.touch_ups import simulate_routes
from model.controllers.anicov.weave import (
    MARGIN,
    WEAVE_CENTRE_LEADS,
    PassLaw,
    one_pass_reach,
    pass_profile,
    sweep_of,
    two_pass_spacing,
)
from model.paper.metrics import pass_reach, straight_pass_coverage
from model.scenario import Scenario, ScenarioError, load_scenario

PAPER = Scenario().with_overrides(controller="anicov", stations=False)  # the spiral's passes weave
WIDE = load_scenario(Path(__file__).resolve().parent.parent / "scenarios" / "wide.toml").with_overrides(
    controller="anicov"
)
LOOKAHEAD_AHEAD = 1.75  # the carrot's mean distance ahead: 2 when given, 1.5 when the next one comes


def profile(scenario: Scenario, amplitude: float) -> tuple[np.ndarray, np.ndarray, float]:
    return pass_profile(amplitude, weave.WAVELENGTH_PER_RANGE * scenario.range, PassLaw.of(scenario))


def test_a_straight_pass_flown_by_the_law_has_fig_7s_profile():
    """Amplitude 0: the profile of the law's own pass is the analytic straight pass of eq. 2 (Fig. 7)
    to the time step, and so are its two-pass spacing and its reach."""
    offsets, coverage, forward = profile(PAPER, 0.0)
    analytic = np.array(
        [straight_pass_coverage(abs(d), PAPER.range, PAPER.half_angle, PAPER.alpha_max) for d in offsets]
    )
    assert forward == pytest.approx(PAPER.k_v, rel=1e-3)
    assert np.max(np.abs(coverage - analytic / PAPER.lambda_star)) < 0.02 * coverage.max()
    assert two_pass_spacing(offsets, coverage) == pytest.approx(best_lane_spacing(PAPER), abs=0.1)
    assert one_pass_reach(offsets, coverage) == pytest.approx(pass_reach(PAPER), abs=0.1)


def test_a_weave_spreads_the_pass_wider_and_thinner():
    """The weave takes ability from the course (a straight pass brings it 5 Λ*) to its sides: the wider the
    weave, the less on the course, the wider the two-pass spacing, the slower forward."""
    amplitudes = (0.0, 0.2, 0.4, 0.5)
    profiles = [profile(PAPER, amplitude) for amplitude in amplitudes]
    on_course = [coverage[np.argmin(np.abs(offsets))] for offsets, coverage, _ in profiles]
    spacings = [two_pass_spacing(offsets, coverage) for offsets, coverage, _ in profiles]
    forwards = [forward for _, _, forward in profiles]
    assert on_course == sorted(on_course, reverse=True) and on_course[0] > 4.0 > 1.0 < on_course[-1]
    assert spacings == sorted(spacings) and spacings[-1] > 1.8 * spacings[0]
    assert forwards == sorted(forwards, reverse=True) and forwards[-1] > 0.8 * PAPER.k_v


def test_the_papers_square_weaves_the_spiral_that_flies_soonest_and_the_strip_flies_straight():
    """sweep_of: of straight passes and every weave that reaches as far alone as a straight pass, the one
    whose spiral flies the domain soonest (length over forward speed); on the paper's square a weave, far
    sooner than straight lanes. On the strip's sensor (R = 10) no weave reaches as far alone as a straight
    pass, so its passes stay straight, exactly as before the weave; ``weave = false`` too."""
    paper = sweep_of(PAPER)
    assert paper.amplitude > 0.0
    offsets, coverage, forward = profile(PAPER, paper.amplitude)
    assert paper.spacing == pytest.approx(MARGIN * two_pass_spacing(offsets, coverage))
    assert paper.reach == pytest.approx(MARGIN * one_pass_reach(offsets, coverage))
    assert paper.reach > pass_reach(PAPER) and paper.edge == pytest.approx(paper.reach / (2.0 * MARGIN))
    assert paper.forward == pytest.approx(forward) and paper.centre_leads == WEAVE_CENTRE_LEADS

    def spiral_time(spacing: float, reach: float, edge: float, speed: float) -> float:
        return Route.of(spiral_in(*PAPER.domain, reach, spacing, edge)).length / speed

    chosen = spiral_time(paper.spacing, paper.reach, paper.edge, paper.forward)
    straight = spiral_time(best_lane_spacing(PAPER), pass_reach(PAPER), pass_reach(PAPER), PAPER.k_v)
    assert chosen < 0.85 * straight
    for amplitude in weave.AMPLITUDES:
        offsets, coverage, forward = profile(PAPER, amplitude)
        reach, spacing = one_pass_reach(offsets, coverage), two_pass_spacing(offsets, coverage)
        if reach >= pass_reach(PAPER):
            assert chosen <= spiral_time(MARGIN * spacing, MARGIN * reach, reach / 2.0, forward) + 1e-9
    for scenario in (WIDE, PAPER.with_overrides(weave=False)):
        straight_sweep = sweep_of(scenario)
        assert straight_sweep.amplitude == 0.0 and straight_sweep.centre_leads == CENTRE_ALLOWANCE_LEADS
        assert (straight_sweep.spacing, straight_sweep.reach, straight_sweep.edge) == (
            best_lane_spacing(scenario),
            pass_reach(scenario),
            pass_reach(scenario),
        )
    with pytest.raises(ScenarioError, match="'weave': expected true or false"):
        PAPER.with_overrides(weave="yes")
    assert weave.LOOKAHEAD == lane_planner.LOOKAHEAD  # the profile's carrots are the planner's


def test_two_weaving_passes_at_the_sweeps_spacing_cover_everything_between_them_on_the_grid():
    """What the profile foretells holds where the engine flies (simulate_routes: the law, eq. 1, the grid's
    fixed-point coverage): two weaving passes the sweep's spacing apart bring every cell between them, away
    from their ends, to Λ*; one pass brings the cells within its reach."""
    scenario = PAPER.with_overrides(domain=[120.0, 60.0])
    sweep = sweep_of(scenario)
    assert sweep.amplitude > 0.0  # a weave (this domain's spiral is soonest weaving too)
    low, high = 30.0 - sweep.spacing / 2.0, 30.0 + sweep.spacing / 2.0
    routes = [np.array([[0.0, low], [120.0, low]]), np.array([[0.0, high], [120.0, high]])]
    lack, _, times = simulate_routes(scenario, routes, np.array([route[0] for route in routes]), lane_planner.LOOKAHEAD)
    rows = np.arange(scenario.grid_shape[0]) + 0.5
    between = (rows > low) & (rows < high)
    assert (lack[between, 40:80] == 0.0).all()
    assert times[0] == pytest.approx(120.0 / sweep.forward, rel=0.03)
    alone, _, _ = simulate_routes(scenario, routes[:1], routes[0][:1], lane_planner.LOOKAHEAD)
    within = np.abs(rows - low) < sweep.reach
    assert (alone[within, 40:80] == 0.0).all()


def test_the_law_steers_the_heading_along_the_weave_with_its_rate_fed_forward():
    """On a straight course, once settled, the heading follows bearing + A sin(2π x/λ) within a fifth of a
    radian (the feed-forward's sign and units: without it the error is 0.49 rad, with it reversed 0.91),
    and the heading swings through about ±A."""
    amplitude, wavelength = 0.45, 3.5
    xs, ys, thetas = weave.flown_course(amplitude, wavelength, PassLaw.of(PAPER), 60.0)
    settled = xs > 20.0
    reference = np.arctan2(-ys, LOOKAHEAD_AHEAD) + amplitude * np.sin(2.0 * np.pi * xs / wavelength)
    error = np.angle(np.exp(1j * (reference - thetas)))[settled]
    assert np.abs(error).max() < 0.25
    assert 0.8 * amplitude < np.abs(thetas[settled]).max() < 1.3 * amplitude
