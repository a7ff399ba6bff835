"""Controllers behind one interface (:mod:`model.controllers.interface`), found by name
(:mod:`model.controllers.registry`): the paper's law and its literal readings, the zig-zag baselines,
anicov's stations, and a user's own (docs/controllers.md)."""

from model.controllers.interface import Controller, RobotView, Supports
from model.controllers.registry import (
    BUILT_IN,
    ControllerError,
    canonical_name,
    check_supports,
    choices,
    controller_of,
    law_of,
    law_parameters,
)

__all__ = [
    "BUILT_IN",
    "Controller",
    "ControllerError",
    "RobotView",
    "Supports",
    "canonical_name",
    "check_supports",
    "choices",
    "controller_of",
    "law_of",
    "law_parameters",
]
