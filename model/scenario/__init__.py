"""A scenario: one coverage problem and team, read from TOML and checked key by key (every concern's keys:
the paper's, the terrain's, the safety filter's, the radio's). The bottom of the model: every other part
reads a :class:`Scenario`, and this package reads none of them."""

from model.scenario.scenario import PAPER_SCENARIO, Scenario, ScenarioError, load_scenario, validate

__all__ = ["PAPER_SCENARIO", "Scenario", "ScenarioError", "load_scenario", "validate"]
