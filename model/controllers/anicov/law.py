"""The anicov controller's step: the paper's sensor with pure pursuit of a carrot (weaving where that
sweeps faster, :mod:`model.controllers.anicov.weave`), a near carrot being a bearing to face at a station."""

from __future__ import annotations

from model.controllers.anicov.route import face_radius_of
from model.controllers.anicov.weave import sweep_of
from model.controllers.interface import paper_law
from model.physics.noise import noise_of
from model.scenario import Scenario
from model.step import LawParameters


def anicov_law(scenario: Scenario, target_ticks: int) -> LawParameters:
    """The compiled law's parameters (:func:`model.paper.control.pursuit_law` through
    :func:`model.step.pursue`): the weave only on the spiral (``stations = false``)."""
    sweep = None if scenario.stations else sweep_of(scenario)
    return paper_law(scenario, target_ticks)._replace(
        pursuit=True,
        weave_amplitude=sweep.amplitude if sweep else 0.0,
        weave_wavelength=sweep.wavelength if sweep else 1.0,
        face_radius=face_radius_of(scenario),
        face_turn_steps=1.0 + noise_of(scenario).command_delay,
    )
