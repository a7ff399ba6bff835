"""anicov.physics_table: issue 37's study table from a map's two sweeps (without and with noise), the goals
checked over every run."""

from __future__ import annotations

import csv
import json

from anicov.physics_table import map_name, physics_table

NOISE = {"localiser_sigma": 0.05, "command_latency": 0.1}
FIGURES = ["completed", "completion_time", "physical_contacts", "true_coverage"]


def sweep_dir(tmp_path, name, base, columns, rows):
    out = tmp_path / name
    out.mkdir()
    (out / "sweep.json").write_text(json.dumps({"base": {"robot_radius": 0.4, **base}}))
    with open(out / "runs.csv", "w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(columns)
        writer.writerows(rows)
    return out


def rooms(tmp_path, noisy_rows):
    plain = sweep_dir(
        tmp_path,
        "rooms",
        {"physics": "mujoco", "noise": {}},
        ["agents", "controller", "physics", "seed", *FIGURES],
        [
            (4, "anicov", "kinematic", 0, True, 100.0, "", ""),  # a kinematic row has no physics figures
            (4, "anicov", "kinematic", 1, True, 120.0, "", ""),
            (4, "anicov", "mujoco", 0, True, 105.0, 0, 1.0),
            (4, "anicov", "mujoco", 1, True, 115.0, 0, 0.9973),
        ],
    )
    noisy = sweep_dir(
        tmp_path,
        "rooms-noise",
        {"physics": "mujoco", "noise": NOISE},
        ["agents", "controller", "seed", *FIGURES],  # physics is fixed, not in the grid
        noisy_rows,
    )
    return [plain, noisy]


def test_a_map_s_two_sweeps_make_one_row_per_team_size_and_controller_with_the_goals_met(tmp_path):
    dirs = rooms(tmp_path, [(4, "anicov", 0, True, 120.0, 0, 1.0), (4, "anicov", 1, True, 130.0, 0, 0.996)])
    lines = physics_table(dirs).splitlines()
    assert lines[0].startswith("| map | N | controller | kinematic | physics (more by) | physics and noise")
    assert lines[1].count("|") == lines[0].count("|")
    assert lines[2] == (
        "| rooms | 4 | anicov | 110.0 | 110.0 (+0.0 %) | 125.0 (+13.6 %) | 2/2 / 2/2 / 2/2 | 0 / 0 "
        "| 99.73 % / 99.60 % | met |"
    )
    assert len(lines) == 3


def test_each_goal_missed_is_named(tmp_path):
    dirs = rooms(
        tmp_path,
        [
            (4, "anicov", 0, True, 150.0, 2, 1.0),  # two contacts; 150 is +36 % over the kinematic 110
            (4, "anicov", 1, False, 900.0, 0, 0.99),  # incomplete, and short in truth
        ],
    )
    row = physics_table(dirs).splitlines()[2]
    assert "| 150.0 (+36.4 %) |" in row  # the incomplete run is left out of the mean
    assert "noise: 1 of 2 incomplete" in row
    assert "noise: 2 contacts" in row
    assert "noise: true coverage 99.00 % < 99.5 %" in row
    assert "noise: +36.4 % over kinematic, not within 15 %" in row
    assert "physics" not in row.split("missed:")[1]  # the physics runs met theirs


def test_physics_without_noise_must_keep_within_the_time_goal_too(tmp_path):
    dirs = rooms(tmp_path, [(4, "anicov", 0, True, 120.0, 0, 1.0)])
    with open(dirs[0] / "runs.csv", "a", newline="") as file:
        csv.writer(file).writerow((4, "anicov", "mujoco", 2, True, 160.0, 0, 1.0))  # physics now 126.7: +15.2 %
    row = physics_table(dirs).splitlines()[2]
    assert "missed: physics: +15.2 % over kinematic, not within 15 %" in row


def test_a_map_s_name_drops_the_noise_suffix(tmp_path):
    assert map_name(tmp_path / "lab-noise") == "lab"
    assert map_name(tmp_path / "lab") == "lab"


def test_a_sweep_whose_noise_holds_only_rules_is_physics_and_a_run_the_goals_cannot_judge_is_named(tmp_path):
    plain = sweep_dir(
        tmp_path,
        "corridor",
        {"physics": "mujoco", "noise": {"cover_margin": 0.05}},  # a rule, not noise
        ["agents", "controller", "seed", *FIGURES],
        [(2, "paper", 0, True, 50.0, 0, ""), (2, "paper", 1, False, 80.0, 0, 1.0)],  # no truth; no kinematic run
    )
    row = physics_table([plain]).splitlines()[2]
    assert row.startswith("| corridor | 2 | paper | — | 50.0 | — | — / 1/2 / — |")
    assert "physics: 1 runs without a true coverage" in row
    assert "physics: no complete kinematic run to time it against" in row
    assert "nan" not in row


def test_seeds_below_k_compare_every_mode_on_the_same_runs(tmp_path):
    """A study in stages may have run one mode to more seeds than another: ``seeds`` keeps the first K of each."""
    dirs = rooms(tmp_path, [(4, "anicov", 0, True, 120.0, 0, 1.0), (4, "anicov", 1, True, 130.0, 0, 0.996)])
    row = physics_table(dirs, seeds=1).splitlines()[2]
    assert row == (
        "| rooms | 4 | anicov | 100.0 | 105.0 (+5.0 %) | 120.0 (+20.0 %) | 1/1 / 1/1 / 1/1 | 0 / 0 "
        "| 100.00 % / 100.00 % | missed: noise: +20.0 % over kinematic, not within 15 % |"
    )
