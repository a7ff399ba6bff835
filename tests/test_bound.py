"""``anicov bound`` (anicov/bound.py): the stations' bound beside t*_N, on the console and in JSON, for a map
with a wall and a door."""

from __future__ import annotations

import json

import pytest

from tests.teamrun import anicov

ROOMS = """
domain = [24.0, 16.0]
cell = 1.0
range = 5.0
robot_radius = 0.4
occlusion = true
obstacles = [[[12, 0], [13, 0], [13, 6], [12, 6]], [[12, 10], [13, 10], [13, 16], [12, 16]]]
"""


def test_the_bound_is_printed_and_written_for_every_team_size(tmp_path):
    config = tmp_path / "rooms.toml"
    config.write_text(ROOMS)
    done = anicov("bound", "--config", str(config), "--teams", "1,2,4", "--out", str(tmp_path / "bound.json"))
    assert done.returncode == 0, done.stderr
    assert "| N | t*_N | stations' bound | bound / t*_N |" in done.stdout
    figures = json.loads((tmp_path / "bound.json").read_text())
    assert figures["unseen_cells"] == 0 and figures["stations"] > 0
    rows = figures["rows"]
    assert [row["agents"] for row in rows] == [1, 2, 4]
    assert rows[1]["stations_bound"] == pytest.approx(rows[0]["stations_bound"] / 2)
    assert rows[2]["optimum_time"] == pytest.approx(rows[0]["optimum_time"] / 4)
    assert all(row["ratio"] >= 1.0 for row in rows)  # no programme beats the sensor's own rate (t*_N)
    for row in rows:
        assert f"| {row['agents']} | {row['optimum_time']:.1f} | {row['stations_bound']:.1f} |" in done.stdout


def test_a_bad_team_size_is_a_clear_error(tmp_path):
    done = anicov("bound", "--teams", "1,x")
    assert done.returncode != 0
    assert "--teams" in done.stderr
