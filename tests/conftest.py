"""Shared fixtures: the paper's scenario."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import settings

from model.scenario import Scenario, load_scenario

ROOT = Path(__file__).resolve().parent.parent

# No per-example deadline: the first example of a property test may load or compile numba kernels
# (half a second or more on a busy machine), and tests must not depend on the machine's speed.
settings.register_profile("anicov", deadline=None)
settings.load_profile("anicov")


@pytest.fixture(scope="session")
def paper_scenario() -> Scenario:
    return load_scenario(ROOT / "scenarios" / "paper.toml")


def write_map(folder: Path, name: str, occupied: np.ndarray, resolution: float = 1.0) -> Path:
    """A ROS map (YAML + PGM) of a bool grid given with row 0 at the bottom (as the model's grid)."""
    image = np.where(np.flipud(occupied), 0, 254).astype(np.uint8)
    cv2.imwrite(str(folder / f"{name}.pgm"), image)
    (folder / f"{name}.yaml").write_text(
        f"image: {name}.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.25\n"
    )
    return folder / f"{name}.yaml"
