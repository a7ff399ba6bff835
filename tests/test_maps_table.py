"""anicov.maps_table: issue 36's study table from one sweep per map, the goals checked over both controllers."""

from __future__ import annotations

import csv
import json

from anicov.maps_table import maps_table

COLUMNS = ["agents", "controller", "seed", "completed", "completion_time", "team_path_length"]
COLUMNS += ["min_separation", "min_clearance"]


def sweep_dir(tmp_path, name, rows, radius=0.4):
    out = tmp_path / name
    out.mkdir()
    (out / "sweep.json").write_text(json.dumps({"base": {"robot_radius": radius, "safety_margin": 0.2}}))
    with open(out / "runs.csv", "w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(COLUMNS)
        writer.writerows(rows)
    return out


def test_a_map_s_rows_give_means_the_gain_and_the_goals_met(tmp_path):
    office = sweep_dir(
        tmp_path,
        "office",
        [
            (1, "paper", 0, True, 200.0, 1000.0, "", 0.7),
            (1, "paper", 1, True, 220.0, 1100.0, "", 0.8),
            (1, "anicov", 0, True, 130.0, 600.0, "", 0.65),
            (1, "anicov", 1, True, 140.0, 700.0, "", 0.61),
            (4, "paper", 0, True, 60.0, 1500.0, 1.3, 0.6),
            (4, "anicov", 0, True, 40.0, 800.0, 1.1, 0.62),
        ],
    )
    lines = maps_table([office]).splitlines()
    assert lines[0].startswith("| map | N | anicov, mean | the paper's law, mean | anicov less by |")
    assert lines[1].count("|") == lines[0].count("|")
    assert lines[2] == "| office | 1 | 135.0 | 210.0 | 35.7 % | 2 / 2, 2 / 2 | 650 / 1,050 | — / 0.610 | met |"
    assert lines[3] == "| office | 4 | 40.0 | 60.0 | 33.3 % | 1 / 1, 1 / 1 | 800 / 1,500 | 1.100 / 0.620 | met |"


def test_each_goal_missed_is_named_and_an_incomplete_run_is_left_out_of_the_mean(tmp_path):
    lab = sweep_dir(
        tmp_path,
        "lab",
        [
            (2, "paper", 0, True, 100.0, 10.0, 0.5, 0.2),
            (2, "paper", 1, False, 900.0, 10.0, 0.15, 0.2),  # incomplete, and two bodies overlapped (0.15 < 2r)
            (2, "anicov", 0, True, 80.0, 5.0, 0.4, 0.09),  # a wall touched (0.09 < r)
        ],
        radius=0.1,
    )
    row = maps_table([lab]).splitlines()[2]
    assert "| 80.0 | 100.0 | 20.0 % | 1 / 1, 1 / 2 |" in row
    assert "paper: 1 incomplete" in row
    assert "paper: a collision (centre gap 0.150 < 2r)" in row
    assert "anicov: a wall contact (clearance 0.090 < r)" in row
    assert "20.0 % less, not 30 %" in row


def test_a_team_size_only_one_controller_ran_is_no_comparison(tmp_path):
    field = sweep_dir(tmp_path, "field", [(8, "anicov", 0, True, 50.0, 5.0, 1.2, 0.6)])
    assert len(maps_table([field]).splitlines()) == 2
