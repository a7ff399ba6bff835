"""The paper's law (eq. 7–16) as a plug-in: the same functions the compiled controller runs, called from Python.

It plans with Algorithms 1–2 (the default planner) and steers toward the objective they give, so a run with
``--controller examples/paper_in_python.py:PaperInPython`` is the ``paper`` controller's run exactly, step for
step (tests/test_plugin_engine.py checks it, byte for byte); bench/bench_plugin.py measures what deciding in
Python costs against the compiled kernel.
"""

from __future__ import annotations

from model.controllers import Controller, RobotView, Supports
from model.paper.control import combined_law, global_law, local_law


class PaperInPython(Controller):
    """eq. 7–9 (local), eq. 10–11 (global, toward the planner's objective), eq. 12–16 (weights, bounds)."""

    name = "paper-in-python"
    supports = Supports(terrain=False, local_planning=False, team=True)

    def command(self, view: RobotView) -> tuple[float, float]:
        s = view.scenario
        u_loc, theta_loc = local_law(view.e_omega, view.w_left, view.w_right, view.theta, s.half_angle)
        u_glo, theta_glo = global_law(view.x, view.y, view.objective_x, view.objective_y, s.range, False)
        return combined_law(
            view.theta, view.e_omega, u_loc, theta_loc, u_glo, theta_glo, s.beta, s.k_v, s.k_omega, False
        )
