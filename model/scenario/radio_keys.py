"""The radio keys of a scenario (issue 13): how far robots hear each other and where planning runs.

- ``comm_range`` (> 0, default unlimited: leave the key out, or ``inf`` in TOML): a robot takes a
  teammate's messages only while their centres are at most this far apart (a filter at the receiver
  stands in for the radio). Replicas then diverge and converge again by anti-entropy on contact
  (:mod:`model.radio.radio`). The coordinator is not a robot: with ``planning = "central"`` it is taken to
  hear everyone (a base station), so only robot-to-robot messages are limited.
- ``planning``: ``"central"`` (default, the paper's: one coordinator runs Algorithms 1-2 for the team)
  or ``"local"``: every robot runs them on its own replica with the teammates it hears and takes its
  own objective (:func:`model.radio.radio.local_members`).
"""

from __future__ import annotations

import math
from typing import Any

RADIO_DEFAULTS: dict[str, Any] = {"comm_range": math.inf, "planning": "central"}
PLANNINGS = ("central", "local")


class RadioKeyError(ValueError):
    """A radio key with a value that cannot be used; the message names the key."""


def resolve_radio_key(key: str, value: Any) -> Any:
    """One radio key's value, checked and typed."""
    if key == "planning":
        if value not in PLANNINGS:
            raise RadioKeyError(f"scenario key 'planning': expected one of {', '.join(PLANNINGS)}, got {value!r}")
        return value
    if isinstance(value, bool) or not isinstance(value, int | float) or math.isnan(value) or value <= 0:
        raise RadioKeyError(f"scenario key 'comm_range': expected a positive number or inf, got {value!r}")
    return float(value)


def check_radio(scenario: Any) -> None:
    """The checks that need the whole scenario; raises RadioKeyError."""
    if scenario.planning == "local" and scenario.objectives:
        raise RadioKeyError(
            "scenario key 'planning': 'local' plans objectives; a scenario with fixed objectives plans none"
        )
    if scenario.filters and scenario.comm_range < scenario.safety_range:
        # The filter reads the poses of the teammates within safety_range: they must be heard.
        raise RadioKeyError(
            f"scenario key 'comm_range': expected at least safety_range ({scenario.safety_range}) so that the "
            f"safety filter hears every teammate it must avoid, got {scenario.comm_range}"
        )
