"""anicov.controller_table: issue 14's table from a sweep's runs.csv, goals checked and misses measured."""

from __future__ import annotations

import csv

import pytest

from anicov.controller_table import controller_table

COLUMNS = ["agents", "controller", "seed", "completed", "time_ratio", "team_path_length"]


def write_runs(path, rows):
    with open(path / "runs.csv", "w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(COLUMNS)
        writer.writerows(rows)


def test_the_table_gives_means_path_shares_completions_and_the_goals(tmp_path):
    write_runs(
        tmp_path,
        [
            (1, "zigzag", 0, True, 3.4, 2000.0),
            (1, "zigzag", 1, True, 3.4, 2000.0),
            (1, "anicov", 0, True, 2.4, 1000.0),
            (1, "anicov", 1, True, 2.6, 1200.0),
            (30, "zigzag", 0, True, 11.0, 3000.0),
            (30, "anicov", 0, False, 9.9, 1000.0),  # not complete: left out of t/t*, counted in the total
            (30, "anicov", 1, True, 3.5, 1100.0),
        ],
    )
    lines = controller_table(tmp_path).splitlines()
    assert lines[0].startswith("| N | zigzag t/t* | anicov t/t* | zigzag path | anicov path | complete |")
    assert lines[2] == "| 1 | 3.40 | 2.50 | 100 % | 55 % | 4/4 | -26.5 % | met | met |"
    assert lines[3] == "| 30 | 11.00 | 3.50 | 150 % | 52 % | 2/3 | -68.2 % | over by 0.50 | met |"


def test_without_a_one_robot_zigzag_there_is_no_yardstick_for_the_path(tmp_path):
    write_runs(tmp_path, [(4, "anicov", 0, True, 3.0, 1000.0)])
    with pytest.raises(ValueError, match="no zigzag run at N = 1"):
        controller_table(tmp_path)
