"""Draws docs/controller/weave_profile.png: one pass's coverage across its course, straight and weaving
(model.controllers.anicov.weave.pass_profile, the paper's sensor), and a weaving pass's path with its wedge at a few steps.

    .venv/bin/python docs/controller/weave_figure.py
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from model.controllers.anicov.weave import (  # noqa: E402
    WAVELENGTH_PER_RANGE,
    PassLaw,
    flown_course,
    pass_profile,
    sweep_of,
    two_pass_spacing,
)
from model.scenario import Scenario  # noqa: E402

AMPLITUDES = (0.0, 0.3, 0.45)
WEDGE_DRAWN = 3.0
"""How much of the wedge's R = 20 is drawn, to keep the drawing readable."""


def main() -> None:
    scenario = Scenario().with_overrides(controller="anicov")
    wavelength = WAVELENGTH_PER_RANGE * scenario.range
    law = PassLaw.of(scenario)
    figure, (across, path) = plt.subplots(1, 2, figsize=(12, 4.5), gridspec_kw={"width_ratios": [1.1, 1]})
    for amplitude in AMPLITUDES:
        offsets, profile, forward = pass_profile(amplitude, wavelength, law)
        spacing = two_pass_spacing(offsets, profile)
        label = "straight" if amplitude == 0.0 else f"weave ±{amplitude:.2f} rad"
        across.plot(offsets, profile, label=f"{label}: two passes {spacing:.1f} apart, {forward:.2f} k_v forward")
    across.axhline(1.0, color="k", lw=0.8, ls="--")
    across.set_ylim(0.0, 5.5)
    across.set_xlim(-12.0, 12.0)
    across.set_xlabel("offset from the course (units)")
    across.set_ylabel("Λ / Λ* after one pass (least-covered phase)")
    across.set_title("One pass of the paper's sensor (R = 20, F = 27°) at k_v")
    across.legend(fontsize=8, loc="upper right")
    sweep = sweep_of(scenario)
    xs, ys, thetas = flown_course(sweep.amplitude, sweep.wavelength, law, 60.0)
    keep = (xs > 20.0) & (xs < 45.0)
    path.plot(
        xs[keep], ys[keep], color="C2", lw=1.5, label=f"path, weave ±{sweep.amplitude:.2f} rad, λ = {wavelength:.1f}"
    )
    for quarter in range(5):  # the wedge at five phases a quarter wavelength apart, a period and more between
        k = int(np.argmin(np.abs(xs - (21.0 + quarter * 1.25 * wavelength))))
        edges = [thetas[k] - scenario.half_angle, thetas[k] + scenario.half_angle]
        tips = [(xs[k] + WEDGE_DRAWN * math.cos(a), ys[k] + WEDGE_DRAWN * math.sin(a)) for a in edges]
        path.fill([xs[k], tips[0][0], tips[1][0]], [ys[k], tips[0][1], tips[1][1]], color="C2", alpha=0.15)
    path.axhline(0.0, color="k", lw=0.8, ls="--", label="course (the carrots' line)")
    path.set_aspect("equal")
    path.set_ylim(-4.0, 4.0)
    path.set_xlabel("along the course (units)")
    path.set_title("The weaving robot and its wedge (the first 3 of R = 20 drawn)")
    path.legend(fontsize=8, loc="lower right")
    figure.tight_layout()
    out = Path(__file__).resolve().parent / "weave_profile.png"
    figure.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
