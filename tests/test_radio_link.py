"""agents.radio.RadioLink: what the simulated radio lets a robot hear, and what its safety filter is shown."""

import math

import numpy as np

from agents.radio import RadioLink
from model.safety.safety import PARKED, TEAMMATE
from model.scenario import Scenario
from protocol.messages import AgentState

TEAMMATES = np.array([TEAMMATE, TEAMMATE, TEAMMATE])


def state_of(agent: int, x: float, y: float) -> AgentState:
    pose = (x, y, 0.0)
    return AgentState(agent, 7, pose, 0.0, 0.0, 0.0, pose)


def test_a_teammate_whose_latest_step_came_from_beyond_range_is_left_out_of_the_filter_until_heard_again():
    """A teammate that walked out of radio range keeps its last heard pose, which ages: the filter stopped the
    robot for it for ever (a realtime team with bodies and comm_range stood still). Its dropped steps say it
    is beyond comm_range (at least safety_range), so the filter is shown no pose for it until one is heard."""
    scenario = Scenario(domain=(40.0, 40.0), agents=3, comm_range=6.0)
    radio = RadioLink(scenario, me=0)
    me = (10.0, 10.0, 0.0)
    poses = np.array([me, (12.0, 10.0, 0.0), (14.0, 10.0, 0.0)])
    assert radio.hears(state_of(1, 12.0, 10.0), me) and radio.hears(state_of(2, 14.0, 10.0), me)
    assert np.array_equal(radio.beyond_reach(poses, TEAMMATES), poses)
    assert not radio.hears(state_of(2, 25.0, 10.0), me)  # 15 away: dropped, counted
    assert radio.out_of_range == 1
    shown = radio.beyond_reach(poses, TEAMMATES)
    assert np.isnan(shown[2]).all() and np.array_equal(shown[:2], poses[:2])
    assert np.array_equal(poses[2], (14.0, 10.0, 0.0))  # the node's own record is left as it was
    parked = np.array([TEAMMATE, TEAMMATE, PARKED])  # it died, or its run is over: its base stands there
    assert np.array_equal(radio.beyond_reach(poses, parked), poses)
    assert radio.hears(state_of(2, 15.0, 10.0), me)  # back in range
    assert np.array_equal(radio.beyond_reach(poses, TEAMMATES), poses)


def test_with_an_unlimited_radio_every_teammate_is_heard_and_shown():
    radio = RadioLink(Scenario(domain=(40.0, 40.0), agents=2), me=0)
    assert math.isinf(radio.scenario.comm_range)
    assert radio.hears(state_of(1, 1000.0, 1000.0), (0.0, 0.0, 0.0))
    poses = np.array([(0.0, 0.0, 0.0), (1000.0, 1000.0, 0.0)])
    assert np.array_equal(radio.beyond_reach(poses, TEAMMATES[:2]), poses)
