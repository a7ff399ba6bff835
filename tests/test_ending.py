"""coordinator.ending: the end of a run, over real Zenoh on loopback with a real team of processes."""

from __future__ import annotations

import numpy as np

from model.paper.fixed_point import COVERAGE_SCALE
from model.scenario import load_scenario
from protocol.decoding import decode
from protocol.keys import TeamKeys
from protocol.messages import Limits, ProtocolError, RunControl
from protocol.recovery import fetch_snapshot
from protocol.session import open_session, zenoh_config
from tests.teamrun import free_port, launched_team, limit, unique_team, wait_for, write_scenario


def test_the_coordinator_stays_on_the_bus_until_the_last_logger_has_the_run_s_end(tmp_path):
    """A logger that is still reading when the run ends (one started by hand, behind on a busy machine) must
    find the coordinator there: its history of gos and its snapshot hold the end of the run. Here the test's
    own session holds a logger's token: after 'done', the coordinator still answers for the final map, and
    leaves as soon as the token is withdrawn."""
    config = write_scenario(tmp_path / "s.toml", domain=[20.0, 20.0], agents=2, seed=3)
    scenario = load_scenario(config)
    team, port = unique_team(), free_port()
    keys, limits = TeamKeys(team), Limits.of(scenario)
    ends: list[RunControl] = []

    def on_control(sample) -> None:
        try:
            message = decode(sample.payload.to_bytes(), limits)
        except ProtocolError:
            return
        if isinstance(message, RunControl) and message.kind == "done":
            ends.append(message)

    with launched_team("--config", str(config), "--no-record", team=team, port=port) as process:
        client = zenoh_config("client", connect=[f"tcp/127.0.0.1:{port}"])
        with open_session(client, patience=limit(120)) as session:
            token = session.liveliness().declare_token(keys.alive("logger"))
            session.declare_subscriber(keys.control, on_control)
            assert wait_for(lambda: bool(ends) or process.poll() is not None, timeout=limit(300))
            assert ends and ends[0].completed, "the run ended without 'done'"
            # Without a logger's token the team is gone in a second or two (the test's bug: a late logger found
            # nobody); with it, the coordinator waits for up to LOGGER_GRACE (10 s) and the team with it.
            assert not wait_for(lambda: process.poll() is not None, timeout=2.0)
            snapshot = fetch_snapshot(session, keys.snapshot, limits, timeout=limit(5))
            assert snapshot is not None and np.all(snapshot.coverage >= round(scenario.lambda_star * COVERAGE_SCALE))
            token.undeclare()
            stdout, stderr = process.communicate(timeout=limit(60))
    assert process.returncode == 0, stderr + stdout
