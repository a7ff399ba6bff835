"""A controller of your own, in about 50 lines: each robot heads for the uncovered cell nearest to it.

Run it (docs/controllers.md walks through it step by step):

    anicov run --controller examples/nearest_uncovered.py:NearestUncovered --n 4 --out runs/mine
    python launch_team.py --controller examples/nearest_uncovered.py:NearestUncovered --n 4

Each step the robot reads its wedge as the paper's robots do (``view.e_omega``, ``view.w_left``,
``view.w_right``: eq. 6 and 9), picks the nearest cell still short of Λ* in its own map, and blends the
paper's local law (eq. 7–9) with the paper's global law toward that cell (eq. 10–11) by the paper's
weights (eq. 12–16). It needs no planner of its own: the default one (Algorithms 1–2) still runs, and this
controller simply does not read the objective it is given.
"""

from __future__ import annotations

import numpy as np

from model.controllers import Controller, RobotView, Supports
from model.paper.control import combined_law, global_law, local_law


class NearestUncovered(Controller):
    """Go to the nearest uncovered cell, covering on the way with the paper's local law."""

    name = "nearest-uncovered"
    supports = Supports(terrain=False, local_planning=False, team=True)

    def command(self, view: RobotView) -> tuple[float, float]:
        scenario = view.scenario
        target_x, target_y = self.nearest_uncovered_cell(view)
        u_loc, theta_loc = local_law(view.e_omega, view.w_left, view.w_right, view.theta, scenario.half_angle)
        u_glo, theta_glo = global_law(view.x, view.y, target_x, target_y, scenario.range, False)
        return combined_law(
            view.theta, view.e_omega, u_loc, theta_loc, u_glo, theta_glo,
            scenario.beta, scenario.k_v, scenario.k_omega, False,
        )  # fmt: skip

    @staticmethod
    def nearest_uncovered_cell(view: RobotView) -> tuple[float, float]:
        """The centre of the nearest cell whose coverage is short of Λ* (the robot itself if none is)."""
        rows, cols = np.nonzero(view.coverage < view.target_ticks)
        if len(rows) == 0:
            return view.x, view.y
        cell = view.scenario.cell
        xs, ys = (cols + 0.5) * cell, (rows + 0.5) * cell
        nearest = int(np.argmin((xs - view.x) ** 2 + (ys - view.y) ** 2))
        return float(xs[nearest]), float(ys[nearest])
