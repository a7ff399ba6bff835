"""A controller of your own, in about 50 lines: each robot heads for the uncovered cell nearest to it.

Run it (docs/controllers.md walks through it step by step):

    anicov run --controller examples/nearest_uncovered.py:NearestUncovered --n 4 --out runs/mine
    python launch_team.py --controller examples/nearest_uncovered.py:NearestUncovered --n 4

Each step the robot reads its wedge as the paper's robots do (``view.e_omega``, ``view.w_left``,
``view.w_right``: eq. 6 and 9) and blends the paper's local law (eq. 7–9) with the paper's global law
(eq. 10–11) toward its target cell, by the paper's weights (eq. 12–16). Its target is the nearest cell still
short of Λ* in its own map, at least R/2 away (the global law stops R/2 short, which frames the cell in
the wedge), kept until it is covered: a target chosen afresh each step flips between two cells at the same
distance and the robot turns on the spot for ever. It needs no planner of its own: the default one
(Algorithms 1–2) still runs, and this controller does not read the objective it gives.
"""

from __future__ import annotations

import numpy as np

from model.controllers import Controller, RobotView, Supports
from model.paper.control import combined_law, global_law, local_law


class NearestUncovered(Controller):
    """Go to the nearest uncovered cell, covering on the way with the paper's local law."""

    name = "nearest-uncovered"
    supports = Supports(terrain=False, local_planning=False, team=True)

    def __init__(self) -> None:
        self.targets: dict[int, tuple[int, int]] = {}  # robot → (row, col) of its target cell

    def command(self, view: RobotView) -> tuple[float, float]:
        s = view.scenario
        row, col = self.target_cell(view)
        target_x, target_y = (col + 0.5) * s.cell, (row + 0.5) * s.cell
        u_loc, theta_loc = local_law(view.e_omega, view.w_left, view.w_right, view.theta, s.half_angle)
        u_glo, theta_glo = global_law(view.x, view.y, target_x, target_y, s.range, False)
        return combined_law(
            view.theta, view.e_omega, u_loc, theta_loc, u_glo, theta_glo, s.beta, s.k_v, s.k_omega, False
        )

    def target_cell(self, view: RobotView) -> tuple[int, int]:
        """This robot's target: kept while short of Λ*, else the nearest short cell at least R/2 away (the
        nearest one if none is that far; the robot's own cell once every cell is covered)."""
        kept = self.targets.get(view.agent)
        if kept is not None and view.coverage[kept] < view.target_ticks:
            return kept
        rows, cols = np.nonzero(view.coverage < view.target_ticks)
        if len(rows) == 0:
            return int(view.y // view.scenario.cell), int(view.x // view.scenario.cell)
        distances = np.hypot((cols + 0.5) * view.scenario.cell - view.x, (rows + 0.5) * view.scenario.cell - view.y)
        framed = distances >= view.scenario.range / 2.0
        nearest = int(np.argmin(np.where(framed, distances, np.inf) if framed.any() else distances))
        self.targets[view.agent] = (int(rows[nearest]), int(cols[nearest]))
        return self.targets[view.agent]
