import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from model.paper.control import combined_law, global_law, local_law

F = math.radians(27.0)
unit = st.floats(0.0, 1.0)
angle = st.floats(-math.pi, math.pi)


def test_local_law_speed_is_one_minus_error():
    assert local_law(0.25, 1.0, 1.0, 0.3, F)[0] == 0.75


def test_local_heading_turns_toward_uncovered_side():
    assert local_law(0.5, 2.0, 0.0, 0.0, F)[1] == pytest.approx(F)  # all uncovered on the left
    assert local_law(0.5, 0.0, 2.0, 0.0, F)[1] == pytest.approx(-F)
    assert local_law(0.5, 1.0, 1.0, 0.4, F)[1] == pytest.approx(0.4)  # balanced: eq. 9 is zero
    assert local_law(0.0, 0.0, 0.0, 0.4, F)[1] == 0.4  # nothing uncovered in view


def test_global_law_speed_eq10_and_heading_toward_objective():
    u, heading = global_law(0.0, 0.0, 10.0, 0.0, 20.0, False)
    assert u == 0.0  # at R/2 from the objective
    assert heading == 0.0
    u_far, heading_up = global_law(0.0, 0.0, 0.0, 500.0, 20.0, False)
    assert u_far == pytest.approx((2 / math.pi) * math.atan(490.0))
    assert heading_up == pytest.approx(math.pi / 2)
    assert global_law(0.0, 0.0, 3.0, 0.0, 20.0, False)[0] < 0.0  # too close: back off


def test_literal_eq11_points_away_from_objective():
    _, heading = global_law(0.0, 0.0, 0.0, 50.0, 20.0, True)
    assert heading == pytest.approx(-math.pi / 2)


@given(
    angle, unit, unit, angle, st.floats(-1.0, 1.0), angle, st.floats(0.1, 5.0), st.floats(0.1, 3.0), st.floats(0.1, 3.0)
)
def test_velocities_stay_in_stated_bounds(theta, e_omega, u_loc, theta_loc, u_glo, theta_glo, beta, k_v, k_omega):
    """eq. 15–16 (chosen reading): v ∈ [−k_v, k_v], ω ∈ [−k_ω π, k_ω π] for any input."""
    v, omega = combined_law(theta, e_omega, u_loc, theta_loc, u_glo, theta_glo, beta, k_v, k_omega, False)
    assert abs(v) <= k_v + 1e-12
    assert abs(omega) <= k_omega * math.pi + 1e-12


def test_literal_eq16_can_exceed_the_stated_bound():
    # u_glo → −1 (right on the objective) doubles the turn rate: the paper's bound fails as printed.
    _, omega = combined_law(0.0, 0.0, 0.0, 0.0, -0.99, math.pi - 0.01, 1.0, 1.0, 1.0, True)
    assert abs(omega) > math.pi


def test_full_local_error_stops_the_agent():
    # e_Ω = 1: W_loc = 1, u_loc = 0 → v = 0, the agent covers where it stands.
    v, _ = combined_law(0.0, 1.0, 0.0, 0.2, 1.0, 2.0, 1.0, 1.0, 1.0, False)
    assert v == 0.0


def test_no_local_error_follows_global_law():
    v, omega = combined_law(0.0, 0.0, 1.0, 0.0, 0.8, 0.5, 1.0, 1.0, 1.0, False)
    assert omega == pytest.approx(0.5)
    assert v == pytest.approx(0.8 * (1 - (2 / math.pi) * 0.5))


def test_pursuit_law_stands_and_turns_toward_a_carrot_within_the_face_radius():
    from model.paper.control import pursuit_law

    # A carrot 0.02 away at bearing 1 rad: stand, turn toward it at the bound (π k_ω), not beyond it.
    v, omega = pursuit_law(5.0, 5.0, 0.0, 5.0 + 0.02 * math.cos(1.0), 5.0 + 0.02 * math.sin(1.0), 1.0, 1.0, 0.1,
                           0.0, 1.0, 0.05)  # fmt: skip
    assert v == 0.0
    assert omega == pytest.approx(math.pi)
    v, omega = pursuit_law(5.0, 5.0, 0.0, 5.0 + 0.02 * math.cos(-0.1), 5.0 + 0.02 * math.sin(-0.1), 1.0, 1.0, 0.1,
                           0.0, 1.0, 0.05)  # fmt: skip
    assert (v, omega) == (0.0, pytest.approx(-1.0))  # reaches the bearing within the step
    # Without a face radius the same carrot is a place to drive to.
    v, _ = pursuit_law(5.0, 5.0, 1.0, 5.0 + 0.02 * math.cos(1.0), 5.0 + 0.02 * math.sin(1.0), 1.0, 1.0, 0.1)
    assert v > 0.0


def facing_errors(turn_steps: float, delay: int, steps: int = 16) -> list[float]:
    """A robot at its station turning to a bearing 0.25 rad away (within a step's reach) when its commands reach
    the wheels ``delay`` steps late: the heading's error after each step."""
    from model.paper.control import pursuit_law

    theta, late, errors = 0.0, [0.0] * delay, []
    for _ in range(steps):
        carrot = (5.0 + 0.02 * math.cos(0.25), 5.0 + 0.02 * math.sin(0.25))
        _, omega = pursuit_law(5.0, 5.0, theta, *carrot, 1.0, 1.0, 0.1, 0.0, 1.0, 0.05, turn_steps)
        late.append(omega)
        theta += late.pop(0) * 0.1
        errors.append(0.25 - theta)
    return errors


def test_a_robot_whose_commands_are_late_turns_to_its_bearing_over_one_step_more_and_settles():
    """Turning the whole error each step, a robot one step late turns it again before the first turn has acted, and
    its heading swings by the whole error for ever (the office, N = 4, commands 0.1 late: 643.8 time units against
    471.6 without; turning over 2 steps, 466.5)."""
    assert max(abs(error) for error in facing_errors(1.0, 0)[1:]) < 1e-12  # no delay: there within the step
    swinging = facing_errors(1.0, 1)
    assert max(abs(error) for error in swinging[-4:]) == pytest.approx(0.25)  # deadbeat, one step late: it swings
    settled = facing_errors(2.0, 1)
    assert max(abs(error) for error in settled[-4:]) < 0.01
