"""Controllers by name: the built-in ones, an installed package's, and a user's own by import path.

``controller = NAME`` in a scenario (``--controller NAME`` on the command line) is, in this order:

1. a built-in name (:data:`BUILT_IN`), or ``best`` (:data:`BEST`: the best controller the project has,
   docs/controller.md; a run records the name it resolved to);
2. a name an installed package declares in the entry point group ``anicov.controllers``
   (``[project.entry-points."anicov.controllers"] mine = "my_package.module:MyController"``);
3. ``module.path:ClassName`` (importable from ``sys.path``) or ``path/to/file.py:ClassName`` (a file,
   relative to the working directory), as pytest plug-ins and uvicorn apps are named.

The class must subclass :class:`model.controllers.interface.Controller`. Anything wrong (a name no one
registers, a module that does not import, a class that is not a controller, a constructor that raises)
raises :class:`ControllerError` naming the controller and what is wrong. This module is the only one that
imports a controller's implementation.
"""

from __future__ import annotations

import functools
import importlib
import importlib.metadata
import importlib.util
import math
import sys
from pathlib import Path

from model.controllers.anicov import AnicovController
from model.controllers.anicov.terrain_stations import Programme, programme_among_walls
from model.controllers.interface import Controller
from model.controllers.paper import PaperController, PaperEq16Controller, PaperLiteralController
from model.controllers.zigzag import BoustrophedonController, ZigzagController
from model.paper.coverage_map import CoverageMap
from model.scenario import Scenario
from model.scenario.physics_keys import sure_doubt_of
from model.step import LawParameters

BUILT_IN: dict[str, type[Controller]] = {
    controller.name: controller
    for controller in (
        PaperController,
        PaperLiteralController,
        PaperEq16Controller,
        ZigzagController,
        BoustrophedonController,
        AnicovController,
    )
}
"""The controllers that ship with anicov, by name (docs/controllers.md)."""
BEST = "anicov"
"""What ``controller = "best"`` names."""
ENTRY_POINT_GROUP = "anicov.controllers"


class ControllerError(ValueError):
    """A controller that cannot be loaded or used; the message names it."""


def canonical_name(name: str, base: Path | None = None) -> str:
    """The name a scenario records: ``best`` resolved, a file path made absolute (relative to ``base``, the
    scenario's folder; default the working directory) so that every process of a team loads the same file;
    raises ControllerError when it loads no controller."""
    if name == "best":
        name = BEST
    if is_file_path(name):
        path, _, attribute = name.rpartition(":")
        name = f"{((base or Path.cwd()) / path).resolve()}:{attribute}"
    _new(name)  # loads it, and makes one: a constructor that raises is found here too
    return name


def controller_of(scenario: Scenario) -> Controller:
    """A new instance of the scenario's controller: one per run, so that what a controller keeps between
    steps (a plug-in may) never leaks from one run of a process (a sweep's worker) into the next."""
    return _new(scenario.controller)


def law_parameters(scenario: Scenario, coverage_map: CoverageMap) -> LawParameters:
    """The scenario's sensor and compiled law (:meth:`model.controllers.interface.Controller.law`), Λ* in the
    map's ticks."""
    return law_of(controller_of(scenario), scenario, coverage_map.target_ticks)


def law_of(controller: Controller, scenario: Scenario, target_ticks: int) -> LawParameters:
    """``controller``'s law (:meth:`model.controllers.interface.Controller.law`) with the doubt the scenario's
    localiser leaves in a robot's pose (:func:`model.scenario.physics_keys.sure_doubt_of`): whatever steers, a
    robot unsure of its pose puts on its map only the coverage it is sure it gave (issue 37, item 4)."""
    law = controller.law(scenario, target_ticks)
    position, heading = sure_doubt_of(scenario)
    if position > 0.0 or heading > 0.0:
        return law._replace(position_doubt=position, heading_doubt=heading)
    return law


def stations_programme(scenario: Scenario) -> Programme:
    """anicov's stations among the scenario's walls and their relaxed programme (``anicov bound``; issue 36,
    items 1 and 6), whichever controller the scenario names."""
    return programme_among_walls(scenario)


def choices() -> tuple[str, ...]:
    """Names the command line offers: the built-in ones, ``best`` and the installed plug-ins'."""
    return (*BUILT_IN, "best", *sorted(_entry_points()))


def check_supports(scenario: Scenario) -> str | None:
    """Why the scenario's controller cannot run it (naming the key), or None."""
    controller = controller_of(scenario)
    supports = controller.supports
    if scenario.has_terrain and not supports.terrain:
        return (
            f"scenario key 'controller': '{scenario.controller}' knows no walls or robot bodies; with map, obstacles "
            f"or robot_radius use one that does: {', '.join(_names_supporting('terrain'))}"
        )
    refused = controller.refuses(scenario)
    if refused is not None:
        return refused
    if scenario.planning == "local" and not supports.local_planning:
        return (
            f"scenario key 'planning': 'local' runs the planner on each robot; controller '{scenario.controller}' "
            f'plans for the whole team at once: use planning = "central"'
        )
    steps = controller.plan_steps(scenario)
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        return (
            f"scenario key 'controller': '{scenario.controller}' plans every {steps!r} steps (plan_steps); "
            "expected a whole number of at least 1"
        )
    if (math.isfinite(scenario.comm_range) or scenario.planning == "local") and not controller.compiled:
        return (
            f"scenario key 'controller': a limited radio and local planning run the compiled controllers only; "
            f"'{scenario.controller}' decides in Python: leave comm_range out (inf) and planning central"
        )
    return None


def _names_supporting(feature: str) -> list[str]:
    return [name for name, controller in BUILT_IN.items() if getattr(controller.supports, feature)]


def _new(name: str) -> Controller:
    controller = controller_class(name)
    try:
        return controller()
    except Exception as error:  # a plug-in's constructor: whatever it raises, name it
        raise ControllerError(f"controller {name!r}: its constructor raised {type(error).__name__}: {error}") from error


@functools.lru_cache(maxsize=32)
def controller_class(name: str) -> type[Controller]:
    """The class a controller name loads (see the module's docstring)."""
    if name in BUILT_IN:
        return BUILT_IN[name]
    entry_points = _entry_points()
    if name in entry_points:
        target = _load(name, entry_points[name].load)
    elif ":" in name:
        target = _load(name, lambda: _import_attribute(name))
    else:
        raise ControllerError(
            f"expected one of {', '.join(choices())}, or module.path:ClassName, or path/to/file.py:ClassName; "
            f"got {name!r}"
        )
    if not (isinstance(target, type) and issubclass(target, Controller)):
        raise ControllerError(
            f"controller {name!r} is {target!r}, not a subclass of model.controllers.interface.Controller"
        )
    return target


def _load(name: str, load: object) -> object:
    try:
        return load()  # type: ignore[operator]
    except ControllerError:
        raise
    except Exception as error:  # an import that fails in a user's module: say which controller it was
        raise ControllerError(f"controller {name!r} cannot be loaded: {type(error).__name__}: {error}") from error


def is_file_path(name: str) -> bool:
    """Whether a controller's name is ``path/to/file.py:ClassName`` (rather than a module path or a name)."""
    path = name.rpartition(":")[0]
    return path.endswith(".py")


def _import_attribute(name: str) -> object:
    module_name, _, attribute = name.rpartition(":")
    if not module_name or not attribute:
        raise ControllerError(f"controller {name!r}: expected module.path:ClassName or path/to/file.py:ClassName")
    if is_file_path(name):
        module = _module_from_file(Path(module_name))
    else:
        module = importlib.import_module(module_name)
    if not hasattr(module, attribute):
        raise ControllerError(f"controller {name!r}: {module_name} has no attribute {attribute!r}")
    return getattr(module, attribute)


def _module_from_file(path: Path) -> object:
    if not path.is_file():
        raise ControllerError(f"controller file {path} does not exist")
    module_name = f"anicov_plugin_{path.stem}_{abs(hash(str(path.resolve())))}"
    if module_name in sys.modules:
        return sys.modules[module_name]
    spec = importlib.util.spec_from_file_location(module_name, path)
    if spec is None or spec.loader is None:
        raise ControllerError(f"controller file {path} is not a Python module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module  # dataclasses and pickling look the module up by name
    spec.loader.exec_module(module)
    return module


def _entry_points() -> dict[str, importlib.metadata.EntryPoint]:
    return {entry.name: entry for entry in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP)}
