import pytest

from protocol.keys import TeamKeys, agent_of_key, check_team_name


def test_keys_live_under_the_team_prefix():
    keys = TeamKeys("alpha")
    assert keys.agent_step(3) == "anicov/alpha/agent/3/step"
    assert keys.all_steps == "anicov/alpha/agent/*/step"
    assert keys.all_histories == "anicov/alpha/agent/*/history"
    assert keys.alive("agent", 2) == "anicov/alpha/alive/agent/2"
    assert agent_of_key(keys.agent_step(12)) == 12
    assert agent_of_key(keys.agent_snapshot(5)) == 5
    assert agent_of_key(keys.alive("agent", 7)) == 7
    assert agent_of_key(keys.objectives) is None


@pytest.mark.parametrize("name", ["", "a/b", "x*", "t**", "a" * 65, "sp ace"])
def test_bad_team_names_are_rejected(name):
    with pytest.raises(ValueError, match="team name"):
        check_team_name(name)
