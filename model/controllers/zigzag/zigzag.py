"""The zig-zag baseline of Fig. 7–8: lanes swept at full speed on the same unicycle and sensor.

Lanes run along x, from −R to W + R (length W + 2R = 140 for the paper's
domain), so every point of a lane's strip passes through the whole wedge.
The first and last lanes lie d100 from the domain's edges (the distance at
which one straight pass reaches Λ*), the rest evenly between. At each lane
end the robot turns in place by 90°, moves to the next lane, and turns 90°
again, at |ω| = k_ω π/2: one time unit per 90° turn, which is what the
paper's t₁ = 2080.6 adds to its path of 2054.6 (docs/paper-notes.md, reading 3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from model.paper.geometry import wrap_angle
from model.paper.metrics import pass_reach
from model.paper.polyline import path_between, point_along
from model.scenario import Scenario

HEADING_TOLERANCE = 1e-6
"""Below this heading error (rad) the pilot drives instead of turning."""
POSITION_TOLERANCE = 1e-6
"""Within this distance (units) a waypoint counts as reached."""


def lane_offsets(height: float, edge_offset: float, lane_spacing_limit: float) -> np.ndarray:
    """Lane positions across the domain: first and last ``edge_offset`` from the edges,
    as few lanes as keep neighbours at most ``lane_spacing_limit`` apart."""
    span = height - 2.0 * edge_offset
    gaps = max(1, math.ceil(span / lane_spacing_limit - 1e-9))
    return edge_offset + np.arange(gaps + 1) * (span / gaps)


def zigzag_waypoints(width: float, lanes: np.ndarray, overhang: float, first_lane_index: int) -> np.ndarray:
    """Waypoints (K, 2) of a boustrophedon over ``lanes``; even global lane indices go +x."""
    points = []
    for offset, lane_y in enumerate(lanes):
        eastward = (first_lane_index + offset) % 2 == 0
        start, end = (-overhang, width + overhang) if eastward else (width + overhang, -overhang)
        points.append((start, lane_y))
        points.append((end, lane_y))
    return np.array(points, dtype=np.float64)


def split_lanes(lanes: np.ndarray, agents: int) -> list[tuple[int, np.ndarray]]:
    """Contiguous blocks of lanes, one per agent: (index of the block's first lane, lanes)."""
    blocks = np.array_split(np.arange(len(lanes)), agents)
    return [(int(block[0]) if block.size else 0, lanes[block]) for block in blocks]


@dataclass
class WaypointPilot:
    """Follows waypoints as a unicycle: turn in place toward the next one, then drive straight."""

    waypoints: np.ndarray
    k_v: float
    turn_rate: float
    dt: float
    next_index: int = 0

    @property
    def finished(self) -> bool:
        return self.next_index >= len(self.waypoints)

    def velocities(self, x: float, y: float, theta: float) -> tuple[float, float]:
        """(v, ω) for the coming step; (0, 0) once the last waypoint is reached."""
        while not self.finished:
            target_x, target_y = self.waypoints[self.next_index]
            distance = math.hypot(target_x - x, target_y - y)
            if distance < POSITION_TOLERANCE:
                self.next_index += 1
                continue
            heading_error = wrap_angle(math.atan2(target_y - y, target_x - x) - theta)
            if abs(heading_error) > HEADING_TOLERANCE:
                turn = min(self.turn_rate, abs(heading_error) / self.dt)
                return 0.0, math.copysign(turn, heading_error)
            return min(self.k_v, distance / self.dt), heading_error / self.dt
        return 0.0, 0.0


def zigzag_pilots(scenario: Scenario) -> list[WaypointPilot]:
    """One waypoint pilot per agent, each sweeping a contiguous block of the Fig. 8 lanes."""
    d100, d50 = pass_reach(scenario), pass_reach(scenario, 0.5)
    lanes = lane_offsets(scenario.domain[1], d100, 2.0 * d50)
    pilots = []
    for first, block in split_lanes(lanes, scenario.agents):
        waypoints = zigzag_waypoints(scenario.domain[0], block, scenario.range, first)
        pilots.append(WaypointPilot(waypoints, scenario.k_v, scenario.k_omega * math.pi / 2.0, scenario.dt))
    return pilots


def boustrophedon_pilots(scenario: Scenario, poses: np.ndarray) -> list[WaypointPilot]:
    """The zig-zag for N robots from anywhere (``controller = "boustrophedon"``): the one-robot path of
    Fig. 8 (lanes d100 from the edges, at most 2·d50 apart: both from eq. 2) cut into N pieces of equal
    length, each robot given the piece whose nearer end it reaches with the least total transit for the
    team (scipy's linear_sum_assignment), flown from that end. A piece that starts at a cut starts R
    earlier along the path: a point is swept by the whole wedge only once the robot has come R toward
    it, so without the overlap the first R of each piece would be seen only in part."""
    from scipy.optimize import linear_sum_assignment

    d100, d50 = pass_reach(scenario), pass_reach(scenario, 0.5)
    lanes = lane_offsets(scenario.domain[1], d100, 2.0 * d50)
    path = zigzag_waypoints(scenario.domain[0], lanes, scenario.range, 0)
    along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
    cuts = np.linspace(0.0, along[-1], scenario.agents + 1)
    firsts = np.array([point_along(path, along, cut) for cut in cuts[:-1]])
    lasts = np.array([point_along(path, along, cut) for cut in cuts[1:]])
    starts = np.asarray(poses)[:, :2]
    to_first = np.linalg.norm(starts[:, None, :] - firsts[None], axis=2)
    to_last = np.linalg.norm(starts[:, None, :] - lasts[None], axis=2)
    robots, chosen = linear_sum_assignment(np.minimum(to_first, to_last))
    pilots: list[WaypointPilot] = [None] * scenario.agents  # type: ignore[list-item]
    for robot, piece in zip(robots, chosen, strict=True):
        low, high = cuts[piece], cuts[piece + 1]
        if to_first[robot, piece] <= to_last[robot, piece]:
            waypoints = path_between(path, max(low - scenario.range, 0.0) if piece > 0 else low, high)
        else:
            last = piece == scenario.agents - 1
            waypoints = path_between(path, low, min(high + scenario.range, along[-1]) if not last else high)[::-1]
        pilots[robot] = WaypointPilot(waypoints.copy(), scenario.k_v, scenario.k_omega * math.pi / 2.0, scenario.dt)
    return pilots


def zigzag_start_poses(scenario: Scenario) -> np.ndarray:
    """Poses at the start of each agent's first lane, facing along it."""
    poses = []
    for pilot in zigzag_pilots(scenario):
        (x0, y0), (x1, y1) = pilot.waypoints[0], pilot.waypoints[1]
        poses.append((x0, y0, math.atan2(y1 - y0, x1 - x0)))
    return np.array(poses, dtype=np.float64)
