"""Scenarios: the paper's setting and the user's own, read from TOML and validated.

Every key is checked on load; a bad file fails at once with a message that
names the key and what is expected. Angles are given in degrees in the file.
"""

from __future__ import annotations

import importlib
import math
import tomllib
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from types import ModuleType
from typing import Any

from model.scenario.physics_keys import PHYSICS_DEFAULTS, PhysicsKeyError, check_physics, resolve_physics_key
from model.scenario.radio_keys import RADIO_DEFAULTS, RadioKeyError, check_radio, resolve_radio_key
from model.scenario.safety_keys import SAFETY_DEFAULTS, SafetyKeyError, check_safety, resolve_safety_key
from model.scenario.terrain import TerrainError
from model.scenario.terrain_keys import resolve_terrain_keys

PAPER_SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "paper.toml"
"""The paper's setting (Section V): the default scenario of every command."""


class ScenarioError(ValueError):
    """A scenario file or value that cannot be used; the message names the key."""


@dataclass(frozen=True)
class Scenario:
    """One coverage problem and team. Units: lengths in domain units, time in time units."""

    domain: tuple[float, float] = (100.0, 100.0)
    cell: float = 1.0
    dt: float = 0.1
    agents: int = 4
    range: float = 20.0
    half_angle_deg: float = 27.0
    alpha_max: float = 50.0
    lambda_star: float = 100.0
    beta: float = 1.0
    k_v: float = 1.0
    k_omega: float = 1.0
    seed: int = 0
    max_time: float = 10000.0
    controller: str = "paper"
    replan_period: float = 5.0
    watchdog: bool = True  # the progress watchdog (model.watchdog): notices, explains and acts on a stall
    watchdog_time: float = 0.0  # how long no cell may be covered before it acts; 0: automatic (model.watchdog)
    weave: bool = True  # anicov: robots weave their heading where that sweeps faster (model.controllers.anicov.weave); false: straight
    stations: bool = True  # anicov: robots stand at stations and turn their camera, hopping between (model.controllers.anicov.stations); false: a spiral
    # Terrain (issue 11); the defaults are the paper's open world and leave every run as it was.
    map: str = ""  # a ROS map YAML, absolute (the file names it relative to itself); "" = none
    obstacles: tuple[tuple[tuple[float, float], ...], ...] = ()  # polygons [[x, y], ...]
    wall_detail: str = "map"  # walls to the map's pixel ("map", up to 5 squares a cell side) or to whole cells ("cell")
    robot_radius: float = 0.0  # r: a robot is a disk (0: the paper's point robot)
    occlusion: bool = True  # walls and teammates' disks hide what lies behind them
    priority_map: str = ""  # an image whose grey level gives Λ*(x) from lambda_star_min to lambda_star
    lambda_star_min: float = 0.0
    # Safety (issue 12, model/scenario_safety.py): the filter acts only on robots with a body.
    safety: bool = True
    safety_margin: float = 0.2
    lookahead: float = 0.2
    barrier_gain: float = 5.0
    safety_range: float = 5.0
    max_pose_age: float = 0.5
    initial_poses: tuple[tuple[float, float, float], ...] = ()  # (x, y, θ in degrees) per robot
    objectives: tuple[tuple[float, float], ...] = ()  # fixed, instead of Algorithms 1-2
    # Radio (issue 13, model/scenario_radio.py): the defaults are the paper's perfect network.
    comm_range: float = math.inf
    planning: str = "central"
    # Units (issue 15): what a length and a time unit are on a real robot (ROS: metres, seconds).
    metres_per_unit: float = 1.0
    seconds_per_unit: float = 1.0
    # Physics (issue 37, model/scenario/physics_keys.py): the default is eq. 1, exactly.
    physics: str = "kinematic"
    robot: tuple[tuple[str, float], ...] = ()  # [robot]: the base's parameters, (name, value) sorted
    noise: tuple[tuple[str, float], ...] = ()  # [noise]: odometry, localiser and command latency, likewise

    @property
    def half_angle(self) -> float:
        """F in radians."""
        return math.radians(self.half_angle_deg)

    @property
    def grid_shape(self) -> tuple[int, int]:
        """(rows, cols) of the coverage grid."""
        return round(self.domain[1] / self.cell), round(self.domain[0] / self.cell)

    @property
    def max_steps(self) -> int:
        return math.ceil(self.max_time / self.dt - 1e-9)

    @property
    def replan_steps(self) -> int:
        return max(1, round(self.replan_period / self.dt))

    @property
    def plan_steps(self) -> int:
        """Steps between two plans, as the controller plans (:meth:`model.controllers.interface.Controller.plan_steps`:
        replan_period's for Algorithms 1-2, a carrot period for anicov's)."""
        return _registry().controller_of(self).plan_steps(self)

    def to_dict(self) -> dict[str, Any]:
        """The scenario as a file would state it; terrain keys only when they differ from the open
        world, so the paper's summary.json is what it always was."""
        values = asdict(self)
        values["domain"] = list(self.domain)
        values["obstacles"] = [[list(point) for point in polygon] for polygon in self.obstacles]
        for key in TERRAIN_KEYS:
            if getattr(self, key) == getattr(_OPEN_WORLD, key) or (key == "occlusion" and not self.has_terrain):
                del values[key]
        for key in ("weave", "stations", "watchdog", "watchdog_time", *UNIT_KEYS, *RADIO_DEFAULTS, *PHYSICS_DEFAULTS):
            if getattr(self, key) == getattr(_OPEN_WORLD, key):
                del values[key]
        for key in ("robot", "noise"):
            if getattr(self, key):
                values[key] = dict(getattr(self, key))
        for key in SAFETY_DEFAULTS:
            unused = key not in ("initial_poses", "objectives") and not self.robot_radius > 0.0
            if getattr(self, key) == SAFETY_DEFAULTS[key] or unused:
                del values[key]
            elif key in ("initial_poses", "objectives"):
                values[key] = [list(point) for point in getattr(self, key)]
        if self.priority_map:
            values["lambda_star"] = values.pop("priority_map")
            values["lambda_star_max"] = self.lambda_star
            values["lambda_star_min"] = self.lambda_star_min
        return values

    @property
    def filters(self) -> bool:
        """Commands pass through the safety filter: robots with a body and ``safety`` on."""
        return self.safety and self.robot_radius > 0.0

    @property
    def has_terrain(self) -> bool:
        """Walls, a map's edge or robots with a body: anything the paper's open world does not have."""
        return bool(self.map or self.obstacles or self.robot_radius > 0.0)

    def with_overrides(self, **overrides: Any) -> Scenario:
        """A validated copy with some keys replaced (``None`` values are ignored)."""
        given = {key: value for key, value in overrides.items() if value is not None}
        values = self.to_dict() | given
        if self.map and "domain" not in given:
            del values["domain"]  # the map's fitted extent depends on the cell (model.scenario.map_fit)
        return validate(values)


UNIT_KEYS = ("metres_per_unit", "seconds_per_unit")
TERRAIN_KEYS = ("map", "obstacles", "wall_detail", "robot_radius", "occlusion", "priority_map", "lambda_star_min")
_OPEN_WORLD = Scenario()

_POSITIVE_FLOATS = (
    "cell",
    "dt",
    "range",
    "alpha_max",
    "lambda_star",
    "beta",
    "k_v",
    "k_omega",
    "max_time",
    "replan_period",
    *UNIT_KEYS,
)


def _number(key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ScenarioError(f"scenario key '{key}': expected a finite number, got {value!r}")
    return float(value)


def _boolean(key: str, value: Any) -> bool:
    """A boolean key's value (TOML true or false), or a ScenarioError naming the key."""
    if not isinstance(value, bool):
        raise ScenarioError(f"scenario key '{key}': expected true or false, got {value!r}")
    return value


def _domain(value: Any) -> tuple[float, float]:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise ScenarioError(f"scenario key 'domain': expected [width, height], got {value!r}")
    width, height = (_number("domain", item) for item in value)
    if width <= 0 or height <= 0:
        raise ScenarioError(f"scenario key 'domain': expected positive sizes, got {value!r}")
    return width, height


def validate(values: dict[str, Any], base: Path | None = None) -> Scenario:
    """Build a Scenario from a mapping, checking every key; raise ScenarioError naming the bad one.
    Files the scenario names (``map``, a priority map) are relative to ``base`` (the scenario's folder)."""
    known = {name for name in Scenario.__dataclass_fields__ if name != "priority_map"} | {"lambda_star_max"}
    unknown = sorted(set(values) - known)
    if unknown:
        raise ScenarioError(f"unknown scenario key '{unknown[0]}': expected one of {', '.join(sorted(known))}")
    try:
        values = resolve_terrain_keys(dict(values), base or Path.cwd())
    except TerrainError as error:
        raise ScenarioError(str(error)) from error
    resolved: dict[str, Any] = {}
    for key, value in values.items():
        if key in TERRAIN_KEYS:
            resolved[key] = value
        elif key in SAFETY_DEFAULTS or key in RADIO_DEFAULTS or key in PHYSICS_DEFAULTS:
            resolved[key] = _grouped_key(key, value)
        elif key == "domain":
            resolved[key] = _domain(value)
        elif key in ("agents", "seed"):
            if isinstance(value, bool) or not isinstance(value, int):
                raise ScenarioError(f"scenario key '{key}': expected an integer, got {value!r}")
            if key == "agents" and not 1 <= value <= 1000:
                raise ScenarioError(f"scenario key 'agents': expected an integer from 1 to 1000, got {value}")
            if key == "seed" and value < 0:
                raise ScenarioError(f"scenario key 'seed': expected a non-negative integer, got {value}")
            resolved[key] = value
        elif key == "controller":
            resolved[key] = _controller_name(value, base)
        elif key in ("weave", "stations", "watchdog"):
            resolved[key] = _boolean(key, value)
        elif key == "watchdog_time":
            patience = _number(key, value)
            if patience < 0.0:
                raise ScenarioError(
                    f"scenario key 'watchdog_time': expected 0 (automatic) or a positive time, got {value!r}"
                )
            resolved[key] = patience
        elif key == "half_angle_deg":
            angle = _number(key, value)
            if not 0.0 < angle < 180.0:
                raise ScenarioError(f"scenario key 'half_angle_deg': expected a number in (0, 180), got {value!r}")
            resolved[key] = angle
        else:
            number = _number(key, value)
            if key in _POSITIVE_FLOATS and number <= 0.0:
                raise ScenarioError(f"scenario key '{key}': expected a positive number, got {value!r}")
            resolved[key] = number
    return _check_whole(replace(Scenario(), **resolved))


def _grouped_key(key: str, value: Any) -> Any:
    """A key of the safety, radio or physics group, resolved by its own module."""
    try:
        if key in SAFETY_DEFAULTS:
            return resolve_safety_key(key, value)
        if key in RADIO_DEFAULTS:
            return resolve_radio_key(key, value)
        return resolve_physics_key(key, value)
    except (SafetyKeyError, RadioKeyError, PhysicsKeyError) as error:
        raise ScenarioError(str(error)) from error


def _check_whole(scenario: Scenario) -> Scenario:
    """The checks that read several keys at once."""
    unsupported = _registry().check_supports(scenario)
    if unsupported:
        raise ScenarioError(unsupported)
    if scenario.map and scenario.metres_per_unit != 1.0:
        raise ScenarioError(
            f"scenario key 'metres_per_unit': a scenario with a map is in the map's units (a Nav2 map's are "
            f"metres): expected 1, got {scenario.metres_per_unit}"
        )
    try:
        check_safety(scenario)
        check_radio(scenario)
        check_physics(scenario)
    except (SafetyKeyError, RadioKeyError, PhysicsKeyError) as error:
        raise ScenarioError(str(error)) from error
    rows, cols = scenario.grid_shape
    for axis, cells, size in (("width", cols, scenario.domain[0]), ("height", rows, scenario.domain[1])):
        if cells < 1 or abs(cells * scenario.cell - size) > 1e-9 * size:
            raise ScenarioError(
                f"scenario key 'cell': expected a size that divides the domain {axis} {size}, got {scenario.cell}"
            )
    return scenario


def _registry() -> ModuleType:
    """The controllers' registry (:mod:`model.controllers.registry`). The scenario is the bottom of the model
    and every controller reads it, so the registry is loaded by name, as a plug-in controller is: the
    ``controller`` key is checked where it is read, and nothing below the controllers imports them."""
    return importlib.import_module("model.controllers.registry")


def _controller_name(value: Any, base: Path | None) -> str:
    """The ``controller`` key: a name the registry loads, recorded as it resolved (``best``: the best one; a
    controller's file, relative to the scenario's folder ``base``, made absolute)."""
    if not isinstance(value, str) or not value:
        raise ScenarioError(f"scenario key 'controller': expected a controller's name, got {value!r}")
    registry = _registry()
    try:
        return registry.canonical_name(value, base)
    except registry.ControllerError as error:
        raise ScenarioError(f"scenario key 'controller': {error}") from error


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise ScenarioError(f"cannot read scenario file {path}: {error.strerror}") from error
    try:
        values = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ScenarioError(f"scenario file {path} is not valid TOML: {error}") from error
    try:
        return validate(values, path.parent)
    except ScenarioError as error:
        raise ScenarioError(f"{path}: {error}") from error
