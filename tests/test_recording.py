"""Recordings read back: the logger process over Zenoh and `anicov run` both write what they claim."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from anicov.engine import run_scenario
from logger.replay import summarise_recording
from model.scenario import load_scenario
from tests.teamrun import anicov, launcher_command, run, write_scenario

EXPECTED_ENTITIES = (
    {
        "/world/domain",
        "/world/map/lack_of_coverage",
        "/world/blobs/segmentation",
        "/world/blobs/objectives",
        "/metrics/e_D",
        "/run/scenario",
        "/run/events",
    }
    | {f"/world/agents/{{i}}/{name}" for name in ("position", "heading", "wedge", "trail", "objective")}
    | {f"/agents/{{i}}/{name}" for name in ("e_omega", "v", "omega")}
)


def expected_entities(agents: int) -> set[str]:
    return {entity.format(i=i) for entity in EXPECTED_ENTITIES for i in range(agents)}


def rerun_cli() -> str:
    return str(Path(sys.executable).parent / "rerun")


def trajectory_rows(path: Path) -> dict[tuple[int, int], tuple[float, float]]:
    with path.open() as handle:
        rows = csv.DictReader(handle)
        return {(round(float(r["t"]) * 10), int(r["agent"])): (float(r["x"]), float(r["y"])) for r in rows}


def check_recording(recording: Path, trajectory: Path, final_lack: np.ndarray, agents: int, cell: float) -> None:
    content = summarise_recording(recording)
    missing = expected_entities(agents) - content.entities
    assert not missing, missing
    assert content.agents == list(range(agents))
    assert content.final_domain_error == 0.0
    assert np.array_equal(content.final_map(), final_lack.astype(np.float32))
    assert_poses_are_the_trajectory(content, trajectory_rows(trajectory), agents)
    # The points are drawn with y up; the images' pixels land on their cells (no map: the model's frame).
    assert np.array_equal(content.transforms["/world/agents"], np.diag([1.0, -1.0, 1.0]))
    rows_in_grid = final_lack.shape[0]
    top_left_pixel_centre = content.transforms["/world/map"] @ np.array([0.5, 0.5, 1.0])
    assert top_left_pixel_centre[:2] == pytest.approx([0.5 * cell, -(rows_in_grid - 0.5) * cell], abs=1e-5)


def assert_poses_are_the_trajectory(content, rows: dict, agents: int) -> None:
    """Every step's pose in the recording is trajectory.csv's, in the map's frame (float32 in the recording)."""
    compared = 0
    for agent, by_step in content.positions.items():
        for step, (x, y) in by_step.items():
            assert (x, y) == pytest.approx(rows[(step, agent)], abs=1e-4)
            compared += 1
    assert compared == len(rows) - agents  # the final rows have no step of their own


def test_launch_team_recording_holds_every_entity_and_matches_the_run(tmp_path):
    config = write_scenario(tmp_path / "s.toml", domain=[40.0, 40.0], agents=2, seed=2)
    launched = run(launcher_command("--config", str(config), "--out", str(tmp_path / "team")))
    assert launched.returncode == 0, launched.stderr + launched.stdout
    recording = tmp_path / "team" / "recording.rrd"
    verified = subprocess.run([rerun_cli(), "rrd", "verify", str(recording)], capture_output=True, text=True)
    assert verified.returncode == 0, verified.stderr
    engine = run_scenario(load_scenario(config))
    check_recording(recording, tmp_path / "team" / "trajectory.csv", engine.final_lack, 2, 1.0)
    content = summarise_recording(recording, load_maps=False)
    assert content.recording_ids == [f"{content.recording_ids[0]}"] and len(content.recording_ids) == 1


def test_anicov_run_writes_a_recording_by_default_and_not_with_no_record(tmp_path):
    config = write_scenario(tmp_path / "s.toml", domain=[30.0, 30.0], agents=3, seed=4)
    done = anicov("run", "--config", str(config), "--out", str(tmp_path / "a"), "--quiet")
    assert done.returncode == 0, done.stderr
    engine = run_scenario(load_scenario(config))
    check_recording(tmp_path / "a" / "recording.rrd", tmp_path / "a" / "trajectory.csv", engine.final_lack, 3, 1.0)
    done = anicov("run", "--config", str(config), "--out", str(tmp_path / "b"), "--quiet", "--no-record")
    assert done.returncode == 0 and not (tmp_path / "b" / "recording.rrd").exists()


def test_replay_summary_prints_what_the_recording_holds(tmp_path):
    config = write_scenario(tmp_path / "s.toml", domain=[30.0, 30.0], agents=2, seed=1)
    assert anicov("run", "--config", str(config), "--out", str(tmp_path), "--quiet").returncode == 0
    summary = anicov("replay", "--summary", str(tmp_path / "recording.rrd"))
    assert summary.returncode == 0, summary.stderr
    text = summary.stdout
    assert "agents           2 (0, 1)" in text
    assert "final e_D        0.000000" in text
    assert "/world/map/lack_of_coverage" in text
    steps = int(text.split("steps            0 .. ")[1].split()[0])
    assert steps == int(__import__("json").loads((tmp_path / "summary.json").read_text())["steps"])


def test_replay_of_a_missing_file_is_a_clear_error(tmp_path):
    done = anicov("replay", "--summary", str(tmp_path / "none.rrd"))
    assert done.returncode == 2 and "no recording at" in done.stderr


def test_serve_hosts_a_web_viewer_and_a_grpc_server_while_the_file_is_still_written(tmp_path):
    """--serve (for a browser on another machine) and the recording file at once: rerun's set_sinks
    replaces sinks, so both must be given together; the file must not lose anything to the server."""
    import socket
    import urllib.request

    from tests.teamrun import free_port, launched_team, limit, wait_for

    web_port, grpc_port = free_port(), free_port()
    out = tmp_path / "run"
    serving = ("--serve", "--web-port", str(web_port), "--grpc-port", str(grpc_port))

    def page() -> bytes:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{web_port}/", timeout=limit(30)) as response:
                return response.read() if response.status == 200 else b""
        except OSError:
            return b""

    square = write_scenario(tmp_path / "s.toml", domain=[60.0, 60.0], agents=4, seed=0)
    with launched_team("--config", str(square), "--out", str(out), *serving) as process:
        served = b""

        def serving() -> bool:  # keeps the page as it first comes: asked again, the run might be over
            nonlocal served
            served = page()
            return served != b""

        assert wait_for(serving, timeout=120)
        assert b"<html" in served.lower()
        with socket.create_connection(("127.0.0.1", grpc_port), timeout=limit(30)):
            pass  # the recording's gRPC server accepts viewers
        stdout, stderr = process.communicate(timeout=limit(400))
    assert process.returncode == 0, stderr + stdout
    announced = (out / "logs" / "logger.log").read_text()
    assert f":{web_port}/?url=rerun+http://" in announced and f":{grpc_port}/proxy" in announced
    assert "0.0.0.0" not in announced
    summary = summarise_recording(out / "recording.rrd")
    assert summary.final_domain_error == 0.0
    assert expected_entities(4) <= set(summary.entities)


def test_a_turned_map_s_recording_is_drawn_in_the_map_s_frame(tmp_path):
    """A map whose origin has a yaw: the recording's poses are trajectory.csv's (the map's frame, as RViz shows
    it), and the map's images are placed, turned, so that each cell's pixel lies where that cell lies."""
    from logger.recording import record_result
    from runtime.rundir import write_run_directory
    from tests.test_map_fit import turned_scenario

    scenario, turned, _, _ = turned_scenario(tmp_path, yaw=0.5)
    result = run_scenario(scenario)
    write_run_directory(result, tmp_path / "out")
    record_result(result, tmp_path / "out" / "recording.rrd", "turned")
    content = summarise_recording(tmp_path / "out" / "recording.rrd")
    assert "/world/map/occupancy" in content.entities
    assert_poses_are_the_trajectory(content, trajectory_rows(tmp_path / "out" / "trajectory.csv"), 1)
    rows, cols = scenario.grid_shape
    for row, col in ((0, 0), (rows - 1, 0), (3, cols - 2)):
        pixel_centre = np.array([col + 0.5, rows - 1 - row + 0.5, 1.0])  # the image is flipped: row 0 at the top
        view = content.transforms["/world/map"] @ pixel_centre
        cell_centre = turned.to_map((col + 0.5) * scenario.cell, (row + 0.5) * scenario.cell)
        assert (view[0], -view[1]) == pytest.approx(cell_centre, abs=1e-4)  # the view's y points down
