"""Shared fixtures: the paper's scenario."""

from __future__ import annotations

from pathlib import Path

import pytest

from anicov.scenario import Scenario, load_scenario

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="session")
def paper_scenario() -> Scenario:
    return load_scenario(ROOT / "scenarios" / "paper.toml")
