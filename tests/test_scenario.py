import pytest

from model.scenario import Scenario, ScenarioError, load_scenario, validate

PAPER_KEYS = {
    "domain",
    "cell",
    "dt",
    "agents",
    "range",
    "half_angle_deg",
    "alpha_max",
    "lambda_star",
    "beta",
    "k_v",
    "k_omega",
    "seed",
    "max_time",
    "controller",
}


def test_paper_file_has_exactly_the_documented_keys(paper_scenario, tmp_path):
    import tomllib

    from tests.conftest import ROOT

    values = tomllib.loads((ROOT / "scenarios" / "paper.toml").read_text())
    assert set(values) == PAPER_KEYS
    assert paper_scenario.domain == (100.0, 100.0)
    assert paper_scenario.half_angle_deg == 27.0
    assert paper_scenario.grid_shape == (100, 100)


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        ("agents", 0, "'agents': expected an integer from 1 to 1000"),
        ("agents", 2.5, "'agents': expected an integer"),
        ("dt", -0.1, "'dt': expected a positive number"),
        ("range", "far", "'range': expected a finite number"),
        ("controller", "magic", "'controller': expected one of paper, paper-literal, paper-eq16, zigzag"),
        ("domain", [100.0], "'domain': expected [width, height]"),
        ("half_angle_deg", 200, "'half_angle_deg': expected a number in (0, 180)"),
        ("cell", 0.3, "'cell': expected a size that divides the domain"),
        ("seed", -1, "'seed': expected a non-negative integer"),
        ("beta", True, "'beta': expected a finite number"),
        ("metres_per_unit", 0.0, "'metres_per_unit': expected a positive number"),
        ("seconds_per_unit", -1.0, "'seconds_per_unit': expected a positive number"),
    ],
)
def test_bad_values_name_the_key_and_what_is_expected(key, value, expected):
    with pytest.raises(ScenarioError, match=expected.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")):
        validate({key: value})


def test_unknown_key_is_rejected_with_the_known_ones():
    with pytest.raises(ScenarioError, match="unknown scenario key 'agent'"):
        validate({"agent": 4})


def test_bad_toml_names_the_file(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("agents = = 4\n")
    with pytest.raises(ScenarioError, match=r"broken\.toml is not valid TOML"):
        load_scenario(path)


def test_missing_file_is_a_clear_error(tmp_path):
    with pytest.raises(ScenarioError, match=r"cannot read scenario file"):
        load_scenario(tmp_path / "nope.toml")


def test_bad_value_in_file_names_file_and_key(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text("agents = -3\n")
    with pytest.raises(ScenarioError, match=r"s.toml: scenario key 'agents'"):
        load_scenario(path)


def test_overrides_are_validated_and_defaults_kept():
    scenario = Scenario().with_overrides(agents=7, seed=None)
    assert scenario.agents == 7 and scenario.seed == 0
    with pytest.raises(ScenarioError):
        Scenario().with_overrides(agents=-1)


def test_units_default_to_one_and_stay_out_of_the_papers_dict(paper_scenario):
    assert (paper_scenario.metres_per_unit, paper_scenario.seconds_per_unit) == (1.0, 1.0)
    assert "metres_per_unit" not in paper_scenario.to_dict() and "seconds_per_unit" not in paper_scenario.to_dict()
    scaled = paper_scenario.with_overrides(metres_per_unit=0.05)
    assert scaled.to_dict()["metres_per_unit"] == 0.05


def test_a_map_is_in_its_own_units(tmp_path):
    from tests.conftest import ROOT

    office = load_scenario(ROOT / "scenarios" / "office.toml")
    with pytest.raises(ScenarioError, match="'metres_per_unit': a scenario with a map is in the map's units"):
        office.with_overrides(metres_per_unit=0.5)
