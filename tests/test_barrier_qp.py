"""The filter's QP (model.safety.barrier_qp) against quadprog's Goldfarb–Idnani solver on random polygons."""

from __future__ import annotations

import numpy as np
import pytest
import quadprog
from hypothesis import example, given, settings
from hypothesis import strategies as st

from model.safety.barrier_qp import project_onto_polygon

finite = st.floats(-5.0, 5.0, allow_nan=False)


@st.composite
def polygons(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[float, float]]:
    """Half-planes g·z ≥ c that all hold with room to spare at some point z0 (a polygon with an inside:
    quadprog calls a polygon of one point inconsistent), and a target."""
    count = draw(st.integers(1, 12))
    angles = np.array(draw(st.lists(st.floats(-np.pi, np.pi), min_size=count, max_size=count)))
    scales = np.array(draw(st.lists(st.floats(0.1, 3.0), min_size=count, max_size=count)))
    slack = np.array(draw(st.lists(st.floats(0.01, 2.0), min_size=count, max_size=count)))
    z0 = np.array([draw(finite), draw(finite)])
    gx, gy = scales * np.cos(angles), scales * np.sin(angles)
    c = gx * z0[0] + gy * z0[1] - slack
    return gx, gy, c, (draw(finite), draw(finite))


@settings(max_examples=400, deadline=None)
@given(polygons())
@example((np.ones(2), np.array([0.0, 4.61555993e-06]), np.array([0.5, 0.5]), (-2.0, 0.0)))
def test_projection_equals_quadprog(polygon: tuple[np.ndarray, np.ndarray, np.ndarray, tuple[float, float]]) -> None:
    gx, gy, c, (tx, ty) = polygon
    feasible, zx, zy = project_onto_polygon(gx, gy, c, len(c), tx, ty)
    assert feasible
    assert np.all(gx * zx + gy * zy >= c - 1e-7)
    # quadprog: min ½ zᵀGz − aᵀz subject to Cᵀz ≥ b, with G = I, a = target: the same projection.
    reference = quadprog.solve_qp(np.eye(2), np.array([tx, ty]), np.stack([gx, gy]), c)[0]
    ours_cost = (zx - tx) ** 2 + (zy - ty) ** 2
    reference_cost = float(np.sum((reference - (tx, ty)) ** 2))
    assert ours_cost == pytest.approx(reference_cost, rel=1e-6, abs=1e-9)
    # The point, to 1e-4: two edges 5e-6 rad apart meet at an ill-conditioned vertex (hypothesis found x ≥ 0.5
    # twice, one tilted so; ours 1.2e-5 off quadprog's along the edge, the cost the same to 1e-10).
    assert np.hypot(zx - reference[0], zy - reference[1]) < 1e-4


def test_feasible_target_is_returned_unchanged() -> None:
    gx, gy, c = np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.array([-1.0, -1.0])
    assert project_onto_polygon(gx, gy, c, 2, 0.3, -0.2) == (True, 0.3, -0.2)


def test_empty_polygon_is_reported() -> None:
    # z_x ≥ 1 and −z_x ≥ 0 (z_x ≤ 0): no point; quadprog agrees.
    gx, gy, c = np.array([1.0, -1.0]), np.array([0.0, 0.0]), np.array([1.0, 0.0])
    assert project_onto_polygon(gx, gy, c, 2, 0.0, 0.0) == (False, 0.0, 0.0)
    with pytest.raises(ValueError, match="inconsistent"):
        quadprog.solve_qp(np.eye(2), np.zeros(2), np.stack([gx, gy]), c)


def test_only_the_first_count_constraints_hold() -> None:
    gx, gy, c = np.array([1.0, 1.0]), np.array([0.0, 0.0]), np.array([2.0, 50.0])
    assert project_onto_polygon(gx, gy, c, 1, 0.0, 0.0) == (True, 2.0, 0.0)
