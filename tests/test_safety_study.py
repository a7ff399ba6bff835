"""anicov safety-study on a tiny grid: the same poses with the filter on and off, one table."""

from __future__ import annotations

import json

from anicov.safety_study import format_table, merge_reports, run_study


def test_a_small_study_compares_the_filter_on_and_off(tmp_path):
    report = run_study(2, [3], tmp_path, workers=1, maps=())
    assert (tmp_path / "safety.md").is_file() and json.loads((tmp_path / "safety.json").read_text()) == report
    (row,) = report["rows"]
    assert (row["domain"], row["agents"], row["runs"]) == ("paper", 3, 2)
    assert row["on"]["collisions"] == 0 and row["on"]["min_separation"] >= 2 * report["radius"]
    assert row["on"]["completed"] == row["off"]["completed"] == 2
    assert "| paper | 3 | 2 | 2 / 2 |" in format_table(report)
    assert len(merge_reports(report, report)["rows"]) == 2
