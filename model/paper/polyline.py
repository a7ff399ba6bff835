"""Polylines: a point at a distance along one, and the stretch between two distances (the zig-zag's lanes
and every route a controller flies are polylines)."""

from __future__ import annotations

import numpy as np


def path_between(waypoints: np.ndarray, start: float, end: float) -> np.ndarray:
    """The stretch of a polyline between two distances along it (start < end), as a polyline."""
    along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1))])
    inner = waypoints[(along > start) & (along < end)]
    return np.vstack([point_along(waypoints, along, start), inner, point_along(waypoints, along, end)])


def point_along(waypoints: np.ndarray, along: np.ndarray, distance: float) -> np.ndarray:
    """The point ``distance`` along a polyline whose cumulative arc lengths are ``along``."""
    segment = min(int(np.searchsorted(along, distance, side="right")) - 1, len(waypoints) - 2)
    share = (distance - along[segment]) / max(along[segment + 1] - along[segment], 1e-300)
    return waypoints[segment] + share * (waypoints[segment + 1] - waypoints[segment])
