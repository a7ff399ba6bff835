"""Shared fixtures: the paper's scenario."""

from __future__ import annotations

from pathlib import Path

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
