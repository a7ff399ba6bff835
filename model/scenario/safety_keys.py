"""The safety keys of a scenario (issue 12), and the poses and objectives a user may fix.

- ``safety`` (true by default): robots with a body (``robot_radius`` > 0) pass every command through
  the safety filter (:mod:`model.safety.safety`); false turns it off for comparison. Point robots never filter.
- ``safety_margin`` s (≥ 0, default 0.2): the filter keeps centres 2r + s apart and disks s off walls.
- ``lookahead`` l (> 0, default 0.2): the distance of the barrier's point ahead of the centre.
- ``barrier_gain`` (> 0, default 5 per time unit): how fast a barrier may close, γ = min(1, gain·dt).
- ``safety_range`` (default 5): teammates farther than this (centre to centre) are not constrained;
  it must be at least what one step and ``max_pose_age`` can close (:func:`least_safety_range`).
- ``max_pose_age`` (> 0, default 0.5 time units): realtime, a teammate in range whose pose is older
  stops the robot; younger, the margin grows by how far it can have moved.
- ``initial_poses = [[x, y, θ_deg], ...]``: the team's poses at t_0, one per robot, instead of the
  seed's draw.
- ``objectives = [[x, y], ...]``: fixed objectives, one per robot, instead of Algorithms 1–2 (a
  mission to given points; the deadlock cases of the tests use it).

With a ``map`` both are in the map's own frame (what RViz shows; :mod:`model.scenario.map_fit`), as
trajectory.csv is: the model takes them out of it (:class:`model.scenario.map_fit.MapFrame`: the fitted map's
corner and the origin's yaw).
"""

from __future__ import annotations

import math
from typing import Any

from model.scenario.map_file import load_map
from model.scenario.map_fit import MapFrame, fit_to_cells
from model.scenario.physics_keys import pair_margin_of

SAFETY_DEFAULTS: dict[str, Any] = {
    "safety": True,
    "safety_margin": 0.2,
    "lookahead": 0.2,
    "barrier_gain": 5.0,
    "safety_range": 5.0,
    "max_pose_age": 0.5,
    "initial_poses": (),
    "objectives": (),
}


class SafetyKeyError(ValueError):
    """A safety key with a value that cannot be used; the message names the key."""


def _number(key: str, value: Any, positive: bool | None = None) -> float:
    """A finite number; ``positive``: True > 0, False ≥ 0, None any sign."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise SafetyKeyError(f"scenario key '{key}': expected a finite number, got {value!r}")
    if positive is not None and (value < 0 or (positive and value == 0)):
        raise SafetyKeyError(
            f"scenario key '{key}': expected a {'positive' if positive else 'non-negative'} number, got {value!r}"
        )
    return float(value)


def _points(key: str, value: Any, size: int) -> tuple[tuple[float, ...], ...]:
    shape = "[x, y, θ_deg]" if size == 3 else "[x, y]"
    if not isinstance(value, list | tuple):
        raise SafetyKeyError(f"scenario key '{key}': expected a list of {shape}, one per robot, got {value!r}")
    points = []
    for index, point in enumerate(value):
        if not isinstance(point, list | tuple) or len(point) != size:
            raise SafetyKeyError(f"scenario key '{key}': entry {index} should be {shape}, got {point!r}")
        points.append(tuple(_number(f"{key}[{index}]", item) for item in point))
    return tuple(points)


def resolve_safety_key(key: str, value: Any) -> Any:
    """One safety key's value, checked and typed."""
    if key == "safety":
        if not isinstance(value, bool):
            raise SafetyKeyError(f"scenario key 'safety': expected true or false, got {value!r}")
        return value
    if key == "initial_poses":
        return _points(key, value, 3)
    if key == "objectives":
        return _points(key, value, 2)
    return _number(key, value, positive=key != "safety_margin")


def point_speed(k_v: float, k_omega: float, lookahead: float) -> float:
    """u_max = √(k_v² + (l·π·k_ω)²): the fastest a look-ahead point moves within the paper's bounds."""
    return math.hypot(k_v, lookahead * math.pi * k_omega)


def least_safety_range(
    radius: float, margin: float, lookahead: float, point_speed: float, dt: float, age: float
) -> float:
    """The smallest safety_range with which a teammate left out cannot reach the barrier in one step:
    the points' clearance 2r + s + 2l, plus 2l from centres to points, plus both points' step and how far
    a teammate's point may have gone in ``age``."""
    return 2.0 * radius + margin + 4.0 * lookahead + point_speed * (2.0 * dt + age)


def check_safety(scenario: Any) -> None:
    """The checks that need the whole scenario (agents, domain, gains); raises SafetyKeyError."""
    frame = MapFrame()
    if scenario.map and (scenario.initial_poses or scenario.objectives):
        frame = fit_to_cells(load_map(scenario.map), scenario.cell).frame  # the poses are in the map's frame
    width, height = scenario.domain
    (low_x, low_y), (high_x, high_y) = frame.corner, frame.to_map(width, height)
    where = f"[{low_x:g}, {high_x:g}] x [{low_y:g}, {high_y:g}]"
    if frame.yaw:
        where = f"{width:g} x {height:g} from ({low_x:g}, {low_y:g}), turned {frame.yaw:g} rad"
    for key in ("initial_poses", "objectives"):
        points = getattr(scenario, key)
        if points and len(points) != scenario.agents:
            raise SafetyKeyError(
                f"scenario key '{key}': expected {scenario.agents} entries (one per robot), got {len(points)}"
            )
        for index, point in enumerate(points):
            model_x, model_y = frame.from_map(point[0], point[1])
            if not (0.0 <= model_x <= width and 0.0 <= model_y <= height):
                in_map = " (in the map's frame)" if scenario.map else ""
                raise SafetyKeyError(
                    f"scenario key '{key}': entry {index} {list(point[:2])} lies outside the domain{in_map} {where}"
                )
    if not scenario.filters:
        return
    point_speed = math.hypot(scenario.k_v, scenario.lookahead * math.pi * scenario.k_omega)
    least = least_safety_range(
        scenario.robot_radius,
        pair_margin_of(scenario),
        scenario.lookahead,
        point_speed,
        scenario.dt,
        scenario.max_pose_age,
    )
    if scenario.safety_range < least:
        raise SafetyKeyError(
            f"scenario key 'safety_range': expected at least {least:.3f} (2r + s + 4l + u_max·(2·dt + max_pose_age)) "
            f"for robot_radius {scenario.robot_radius} and s {pair_margin_of(scenario):.3f} (safety_margin plus two "
            f"robots' clearance reserves, with physics), got {scenario.safety_range}"
        )
