"""The logger's decisions without Zenoh: what each message becomes in the recording, read back from the file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rerun.chunk import RrdReader

from logger.replay import format_recording_summary, summarise_recording
from logger.team_logger import LoggerOptions, TeamLogger
from model.scenario import Scenario
from protocol.inbox import Membership, Received
from protocol.keys import TeamKeys
from protocol.messages import (
    AgentState,
    AgentStep,
    MapDelta,
    Objectives,
    RunControl,
    Snapshot,
    StepGo,
    Traffic,
    encode,
)

SCENARIO = Scenario()  # the paper's: a 100 × 100 grid of unit cells, 4 agents, Λ* = 100
ROWS, COLS = SCENARIO.grid_shape
CELLS = ROWS * COLS


def make_logger(tmp_path: Path, map_every: int = 2) -> tuple[TeamLogger, Path]:
    path = tmp_path / "recording.rrd"
    return TeamLogger(SCENARIO, LoggerOptions("t", "test-recording", str(path), map_every=map_every)), path


def target_ticks(node: TeamLogger) -> int:
    return node.replica.map.target_ticks


def window(node: TeamLogger, agent: int, seq: int, row0: int, col0: int, fraction: float = 1.0) -> MapDelta:
    """A 10 × 10 window of ``fraction`` of the target coverage."""
    ticks = np.full((10, 10), round(fraction * target_ticks(node)), dtype=np.int64)
    return MapDelta(agent, seq, row0, col0, ticks)


def state(agent: int, step: int, x: float, y: float) -> AgentState:
    return AgentState(agent, step, (x, y, 0.0), 1.0, 0.1, 0.5, (x + 1.0, y, 0.0))


def received(message) -> Received:
    return Received("anicov/t/coordinator/go", message)


def events(path: Path) -> list[tuple[int, str, str]]:
    """(step, level, text) of every event in the recording, in order."""
    found = []
    for chunk in RrdReader(str(path)).stream():
        if str(chunk.entity_path) == "/run/events":
            batch = chunk.to_record_batch()
            steps = batch.column("step").to_pylist()
            levels = batch.column("TextLog:level").to_pylist()
            texts = batch.column("TextLog:text").to_pylist()
            found += [(s, level[0], text[0]) for s, level, text in zip(steps, levels, texts, strict=True)]
    return found


def lockstep_run(node: TeamLogger) -> list[StepGo]:
    """Three gos: step 0 (nothing before it), step 1 (agents 0 and 1 each cover a window), step 2 (agent 0
    half covers a third, with objectives and blobs)."""
    everyone = tuple(range(4))
    objectives = Objectives(
        2,
        everyone,
        np.array([[50.0, 50.0], [60.0, 50.0], [70.0, 50.0], [80.0, 50.0]]),
        np.array([[55.0, 55.0]]),
        np.ones((ROWS, COLS), dtype=np.uint16),
    )
    return [
        StepGo(0, everyone, ()),
        StepGo(
            1,
            everyone,
            (window(node, 0, 0, 0, 0), window(node, 1, 0, 0, 10)),
            None,
            tuple(state(agent, 0, 10.0 * agent, 40.0) for agent in everyone),
        ),
        StepGo(
            2,
            everyone,
            (window(node, 0, 1, 10, 0, 0.5),),
            objectives,
            tuple(state(agent, 1, 10.0 * agent + 1.0, 40.0) for agent in everyone),
        ),
    ]


def test_lockstep_gos_become_the_map_the_error_the_poses_and_the_objectives(tmp_path):
    node, path = make_logger(tmp_path)
    for go in lockstep_run(node):
        node.handle(received(go))
    node.handle(received(RunControl("done", 2, True, 0.975, "")))
    assert node.finished is not None and node.finished.step == 2
    node.finish()

    content = summarise_recording(path)
    assert content.recording_ids == ["test-recording"]
    assert content.agents == [0, 1, 2, 3]
    # e_D after each step: two windows of 100 cells covered, then half of a third.
    assert content.domain_error == pytest.approx({1: 1 - 200 / CELLS, 2: 1 - 250 / CELLS})
    assert content.final_domain_error == pytest.approx(0.975)
    final = content.final_map()
    assert max(content.maps) == 2
    assert np.array_equal(final, node.replica.map.lack_of_coverage().astype(np.float32))
    assert (final[0:10, 0:20] == 0.0).all() and (final[10:20, 0:10] == 0.5).all()
    assert final.sum() == pytest.approx(CELLS - 250)
    # Every agent's pose of steps 0 and 1, in the map's frame (here the model's).
    for agent in range(4):
        assert content.positions[agent] == {
            0: pytest.approx((10.0 * agent, 40.0)),
            1: pytest.approx((10.0 * agent + 1.0, 40.0)),
        }
    assert {"/world/blobs/objectives", "/world/blobs/segmentation"} <= content.entities
    assert {f"/world/agents/{agent}/objective" for agent in range(4)} <= content.entities
    assert events(path) == [(2, "INFO", "run complete")]


def test_a_go_read_twice_is_taken_once(tmp_path):
    node, _ = make_logger(tmp_path)
    gos = lockstep_run(node)
    for go in (gos[0], gos[1], gos[1], gos[2], gos[1], gos[0]):
        node.handle(received(go))
    assert node.next_go == 3
    assert node.replica.duplicates == 0  # the repeated gos never reached the map
    assert node.replica.map.domain_error() == pytest.approx(1 - 250 / CELLS)
    node.finish()


def test_realtime_steps_membership_and_an_abort(tmp_path):
    node, path = make_logger(tmp_path)
    node.handle(Membership(1, True))
    node.handle(received(AgentStep(window(node, 1, 0, 50, 50), state(1, 0, 55.0, 45.0))))
    node.handle(received(RunControl("status", 1, False, 0.99, "")))  # a status does not end the run
    assert node.finished is None
    node.handle(Membership(1, False))
    node.handle(received(RunControl("abort", 1, False, 0.99, "coordinator lost")))
    node.finish()

    content = summarise_recording(path)
    assert content.positions == {1: {0: pytest.approx((55.0, 45.0))}}
    assert content.domain_error == pytest.approx({1: 1 - 100 / CELLS})
    assert (content.final_map()[50:60, 50:60] == 0.0).all()
    assert events(path) == [
        (0, "INFO", "agent 1 joined"),
        (1, "WARN", "agent 1 left"),
        (1, "INFO", "run ended: coordinator lost"),
    ]


def test_traffic_reports_become_bytes_per_second_and_a_table(tmp_path):
    node, path = make_logger(tmp_path)
    for report in (
        Traffic("agent", 2, 1.0, 1_000, 5_000),
        Traffic("agent", 2, 3.0, 3_000, 9_000),  # 1,000 B/s out, 2,000 B/s in over those 2 s
        Traffic("coordinator", 0, 2.0, 500, 800),  # a first report: nothing to compare with yet
        Traffic("agent", 2, 0.5, 100, 100),  # restarted: its counters start again, no negative rate
        Traffic("agent", 2, 1.5, 600, 2_100),  # 500 B/s out, 2,000 B/s in since the restart
    ):
        node.handle(Received(f"anicov/t/traffic/{report.role}/{report.ident}", report))
    node.finish()

    content = summarise_recording(path)
    assert content.traffic == {
        ("agent-2", "bytes_out"): [1000.0, 500.0],
        ("agent-2", "bytes_in"): [2000.0, 2000.0],
    }
    assert node.bandwidth()["agent-2"] == {
        "seconds": 1.5,
        "bytes_out": 600,
        "bytes_in": 2_100,
        "bytes_out_per_second": 400.0,
        "bytes_in_per_second": 1400.0,
    }
    assert node.bandwidth()["coordinator-0"]["bytes_in_per_second"] == 400.0
    assert "/run/bandwidth" in content.entities
    assert "bus agent-2      out 750 B/s, in 2000 B/s" in format_recording_summary(content)


def test_an_abort_without_a_reason_and_a_stop_before_the_end(tmp_path):
    node, path = make_logger(tmp_path / "abort")
    node.handle(received(RunControl("abort", 0, False, 1.0, "")))
    node.finish()
    assert events(path) == [(0, "INFO", "run ended: incomplete")]

    node, path = make_logger(tmp_path / "stopped")
    node.handle(received(state(0, 3, 5.0, 5.0)))  # a late start: the first state it sees is of step 3
    node.finish()
    assert events(path) == [(4, "INFO", "logger stopped before the end of the run")]
    content = summarise_recording(path)
    assert content.domain_error == {4: 1.0}
    assert max(content.maps) == 4 and (content.final_map() == 1.0).all()


def test_objectives_draw_a_line_only_from_agents_whose_position_is_known(tmp_path):
    node, path = make_logger(tmp_path)
    node.handle(received(state(0, -1, 10.0, 20.0)))  # a hello: a position, no step recorded
    node.handle(received(Objectives(0, (0, 1), np.array([[30.0, 30.0], [40.0, 40.0]]))))
    node.finish()

    content = summarise_recording(path)
    assert content.positions == {}
    assert "/world/agents/0/objective" in content.timed
    assert "/world/agents/1/objective" not in content.entities
    assert "/world/blobs/objectives" not in content.timed  # no blobs in these objectives (only its static frame)
    assert "/world/blobs/segmentation" not in content.timed  # nor labels


def test_a_snapshot_fills_the_map_and_skips_the_gos_already_in_it(tmp_path):
    node, path = make_logger(tmp_path)
    coverage = np.zeros((ROWS, COLS), dtype=np.int64)
    coverage[90:, 90:] = target_ticks(node)
    node.load_snapshot(Snapshot(coverage, {0: (6, ()), 1: (5, (7,))}))
    assert node.next_go == 7  # the deltas of steps up to 5 are in the map: the gos up to 6 carry them
    assert node.replica.map.domain_error() == pytest.approx(1 - 100 / CELLS)

    # Go 6 carries step 5, already in the map: skipped whole (its state too). Go 7 carries agent 1's step 6.
    node.handle(received(StepGo(6, (0, 1), (window(node, 1, 5, 0, 0),), None, (state(1, 5, 1.0, 1.0),))))
    node.handle(received(StepGo(7, (0, 1), (window(node, 1, 6, 0, 0),), None, (state(1, 6, 2.0, 1.0),))))
    node.handle(received(RunControl("done", 7, False, 0.98, "")))
    assert node.replica.duplicates == 0
    node.finish()
    content = summarise_recording(path)
    assert content.positions == {1: {6: pytest.approx((2.0, 1.0))}}
    final = content.final_map()
    assert (final[90:, 90:] == 0.0).all() and (final[0:10, 0:10] == 0.0).all()
    assert final.sum() == pytest.approx(CELLS - 200)
    assert content.domain_error == pytest.approx({7: 1 - 200 / CELLS})
    assert events(path) == [(7, "INFO", "run ended: incomplete")]


def test_a_snapshot_of_a_fresh_run_keeps_the_first_go(tmp_path):
    node, _ = make_logger(tmp_path)
    node.load_snapshot(Snapshot(np.zeros((ROWS, COLS), dtype=np.int64), {}))
    assert node.next_go == 0
    node.finish()


def test_payloads_through_the_inbox_reach_the_logger_only_when_valid(tmp_path):
    """The process's path, without a session: deferred decoding on the main thread, then ``handle``."""
    node, path = make_logger(tmp_path)
    keys = TeamKeys("t")
    for go in lockstep_run(node):
        node.inbox.deliver(keys.go_history, encode(go), recovery=False)
    node.inbox.deliver(keys.control, b"\x93garbage", recovery=False)
    node.inbox.deliver(keys.control, encode(RunControl("done", 2, True, 0.975, "")), recovery=False)
    while (item := node.inbox.get(timeout=0)) is not None:
        node.handle(item)
    assert node.inbox.counts()["accepted"] == 4 and node.inbox.counts()["rejected"] == 1
    node.finish()
    content = summarise_recording(path)
    assert content.final_domain_error == pytest.approx(1 - 250 / CELLS)
    assert events(path) == [(2, "INFO", "run complete")]
