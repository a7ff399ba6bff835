"""Reference quantities of Section V: total sensing ability (eq. 18), optimum time (eq. 19),
and the coverage profile of one straight pass (Fig. 7) with its d100 and d50."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from scipy import integrate, optimize

from model.paper.sensing import sensing_ability

if TYPE_CHECKING:
    from model.scenario import Scenario


def total_sensing_ability(sensing_range: float, half_angle: float, alpha_max: float) -> float:
    """𝒜 = 2 ∫₀^F ∫₀^R α(r, θ) r dr dθ, eq. 18; in closed form α_M R² F / 6."""
    value, _ = integrate.dblquad(
        lambda r, angle: sensing_ability(r, angle, sensing_range, half_angle, alpha_max) * r,
        0.0,
        half_angle,
        0.0,
        sensing_range,
    )
    return 2.0 * value


def optimum_time(domain_area: float, lambda_star: float, total_ability: float, agents: int) -> float:
    """t*_N = ∫∫ Λ* dx / (𝒜 N), eq. 19, for a uniform Λ*."""
    return domain_area * lambda_star / (total_ability * agents)


def straight_pass_coverage(
    offset: float, sensing_range: float, half_angle: float, alpha_max: float, speed: float = 1.0
) -> float:
    """Λ gained by a point ``offset`` to the side of one infinite straight pass at ``speed`` (Fig. 7).

    The agent at (s, 0) heading +x sees the point (0, d) at distance √(s² + d²)
    and bearing atan2(d, −s); coverage is ∫ α ds / speed over the pass.
    """
    reach = math.sqrt(max(sensing_range**2 - offset**2, 0.0))

    def ability_along(s: float) -> float:
        distance = math.hypot(s, offset)
        bearing = abs(math.atan2(offset, -s))
        return sensing_ability(distance, bearing, sensing_range, half_angle, alpha_max)

    value, _ = integrate.quad(ability_along, -reach, 0.0, limit=200)
    return value / speed


def coverage_distance(level: float, sensing_range: float, half_angle: float, alpha_max: float) -> float:
    """Side distance at which one straight pass at v = 1 yields coverage ``level`` (d100, d50)."""
    return optimize.brentq(
        lambda d: straight_pass_coverage(d, sensing_range, half_angle, alpha_max) - level,
        1e-9,
        sensing_range * math.sin(half_angle) - 1e-9,
        xtol=1e-12,
    )


def pass_reach(scenario: Scenario, share: float = 1.0) -> float:
    """:func:`coverage_distance` of the scenario's sensor at ``share`` of Λ*: d100 (1.0) or d50 (0.5)."""
    return coverage_distance(scenario.lambda_star * share, scenario.range, scenario.half_angle, scenario.alpha_max)
