"""model.scenario.terrain_keys: the terrain keys of a scenario, checked before anything runs."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from model.scenario import PAPER_SCENARIO, ScenarioError, load_scenario, validate
from tests.conftest import ROOT, write_map
from tests.teamrun import anicov, write_scenario

MAPS = ROOT / "scenarios" / "maps"


def test_a_map_gives_the_domain_and_the_cell_relative_to_the_scenario_file(tmp_path):
    shutil.copy(MAPS / "office.yaml", tmp_path / "office.yaml")
    shutil.copy(MAPS / "office.pgm", tmp_path / "office.pgm")
    scenario = load_scenario(write_scenario(tmp_path / "s.toml", map="office.yaml"))
    assert scenario.domain == (100.0, 100.0) and scenario.cell == 0.5  # the map's resolution
    assert scenario.map == str((tmp_path / "office.yaml").resolve())
    assert scenario.with_overrides(agents=3).map == scenario.map  # survives a round trip through to_dict


def test_the_papers_scenario_reports_exactly_the_keys_it_always_did():
    assert set(load_scenario(PAPER_SCENARIO).to_dict()) == {
        *("domain", "cell", "dt", "agents", "range", "half_angle_deg", "alpha_max", "lambda_star"),
        *("beta", "k_v", "k_omega", "seed", "max_time", "controller", "replan_period"),
    }


def test_a_terrain_scenario_reports_its_terrain_keys():
    values = validate({"domain": [20.0, 20.0], "robot_radius": 0.4, "occlusion": False}).to_dict()
    assert values["robot_radius"] == 0.4 and values["occlusion"] is False


@pytest.mark.parametrize(
    ("values", "expected"),
    [
        ({"map": "nowhere.yaml"}, r"'map': the map file .*nowhere.yaml does not exist"),
        ({"map": 3}, r"'map': expected the path of a ROS map YAML file"),
        ({"map": "maps/office.yaml", "domain": [50.0, 50.0]}, r"'domain': the map .* spans \[100.0, 100.0\]"),
        ({"map": "maps/office.yaml", "cell": 0.75}, r"'cell': expected a whole multiple of the map's resolution 0.5"),
        ({"obstacles": [[[0, 0], [1, 1]]]}, r"'obstacles\[0\]': expected a polygon \[\[x, y\], \.\.\.\] of 3"),
        ({"obstacles": [[[0, 0], [2, 2], [2, 0], [0, 2]]]}, r"'obstacles\[0\]': the polygon crosses itself"),
        ({"obstacles": [[[0, 0], [1, 1], [2, 2]]]}, r"'obstacles\[0\]': the polygon has no area"),
        ({"obstacles": "wall"}, r"'obstacles': expected a list of polygons"),
        ({"robot_radius": -1.0}, r"'robot_radius': expected a finite number of at least 0.0"),
        ({"occlusion": "yes"}, r"'occlusion': expected true or false"),
        ({"lambda_star": "nowhere.png"}, r"'lambda_star': the priority image .*nowhere.png does not exist"),
        ({"lambda_star_min": 3.0}, r"'lambda_star_min': only with lambda_star naming a priority image"),
        ({"robot_radius": 0.5, "controller": "zigzag"}, r"'controller': 'zigzag' knows no walls or robot bodies"),
    ],
)
def test_bad_terrain_keys_name_the_key_and_what_is_expected(values, expected):
    with pytest.raises(ScenarioError, match=expected):
        validate(values, ROOT / "scenarios")


def test_a_file_that_is_not_a_map_is_refused_with_its_name(tmp_path):
    (tmp_path / "bad.yaml").write_text("just: text\n")
    with pytest.raises(ScenarioError, match=r"map .*bad.yaml: missing key 'image'"):
        validate({"map": "bad.yaml"}, tmp_path)
    (tmp_path / "picture.yaml").write_text((MAPS / "office.yaml").read_text().replace("office.pgm", "picture.pgm"))
    (tmp_path / "picture.pgm").write_bytes(b"not an image")
    with pytest.raises(ScenarioError, match=r"map .*picture.yaml: its image .*picture.pgm is not a PGM or PNG image"):
        validate({"map": "picture.yaml"}, tmp_path)


def test_a_map_with_no_free_cell_and_a_team_too_big_fail_before_any_process_starts(tmp_path):
    write_map(tmp_path, "solid", np.ones((10, 10), dtype=bool))
    done = anicov("run", "--config", str(write_scenario(tmp_path / "a.toml", map="solid.yaml")), "--out", str(tmp_path))
    assert done.returncode == 2 and "solid.yaml" in done.stderr and "has no free cell" in done.stderr
    room = np.ones((10, 10), dtype=bool)
    room[4:6, 4:6] = False  # room for one robot of radius 0.4, not for three
    write_map(tmp_path, "cell", room)
    # The terrain rule alone (issue 11): the safety filter's margin would leave no room at all.
    config = write_scenario(tmp_path / "b.toml", map="cell.yaml", robot_radius=0.4, agents=3, safety=False)
    done = anicov("run", "--config", str(config), "--out", str(tmp_path / "b"))
    assert done.returncode == 2 and "cell.yaml" in done.stderr and "cannot hold 3 robots" in done.stderr
    assert not (tmp_path / "b").exists()
