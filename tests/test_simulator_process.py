"""simulator.process: ``anicov sim`` as a real process on a real Zenoh router on loopback, driven by hand with
ROS 2 messages (Twist in, Odometry out, CDR by rosbags) as the agents' driver would."""

from __future__ import annotations

import json
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import pytest
import zenoh

from protocol.keys import TeamKeys
from protocol.ros2.messages import decode_pose, encode_velocity
from protocol.ros2.options import ODOMETRY
from protocol.session import zenoh_config
from runtime.lifecycle import EXIT_SIGTERM
from tests.teamrun import anicov, anicov_command, free_port, limit, running, unique_team, wait_for

ROOM = """domain = [12.0, 8.0]
cell = 1.0
range = 3.0
robot_radius = 0.3
agents = 2
seed = 1
controller = "anicov"
physics = "mujoco"
"""
PERIOD_NS = 100_000_000  # dt 0.1 at one second per unit


@dataclass
class Bus:
    """A client session beside the simulator: what each base published (stamp, x) and a way to command it."""

    session: zenoh.Session
    keys: TeamKeys
    out: Path
    seen: dict[int, list[tuple[int, float, float]]] = field(default_factory=lambda: {0: [], 1: []})
    lock: threading.Lock = field(default_factory=threading.Lock)

    def on_odometry(self, agent: int, sample: zenoh.Sample) -> None:
        read = decode_pose(sample.payload.to_bytes(), ODOMETRY)
        with self.lock:
            self.seen[agent].append((read.stamp_ns, read.pose[0], read.pose[1]))

    def newest(self, agent: int) -> tuple[int, float, float] | None:
        with self.lock:
            return max(self.seen[agent], default=None)

    def stamped(self, stamp: int) -> bool:
        """Both bases published the instant ``stamp``."""
        return all((newest := self.newest(agent)) is not None and newest[0] >= stamp for agent in (0, 1))

    def command(self, agent: int, linear: float, angular: float = 0.0) -> None:
        self.session.put(f"bot{agent}/cmd_vel", encode_velocity(linear, angular, stamped=False))


@contextmanager
def simulator(tmp_path: Path, clock: str, *flags: str) -> Iterator[tuple[Bus, object]]:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    config = tmp_path / "room.toml"
    config.write_text(ROOM)
    team = unique_team()
    with zenoh.open(zenoh_config("router", listen=[endpoint])), zenoh.open(zenoh_config(connect=[endpoint])) as session:
        bus = Bus(session, TeamKeys(team), tmp_path / "out")
        for agent in (0, 1):
            session.declare_subscriber(f"bot{agent}/odom", lambda sample, agent=agent: bus.on_odometry(agent, sample))
        command = anicov_command(
            "sim", "--config", str(config), "--team", team, "--connect", endpoint, "--clock", clock,
            "--out", str(bus.out), *flags,
        )  # fmt: skip
        with running(command) as process:
            yield bus, process


def test_in_lockstep_the_world_steps_once_every_live_agents_command_is_in(tmp_path):
    with simulator(tmp_path, "lockstep") as (bus, process):
        assert wait_for(lambda: bus.stamped(0), 60), "the simulator never published its bases' start poses"
        stranger = bus.session.liveliness().declare_token(bus.keys.alive("agent", 7))  # no such robot: ignored
        tokens = [bus.session.liveliness().declare_token(bus.keys.alive("agent", agent)) for agent in (0, 1)]
        start = bus.newest(0)
        bus.command(0, 0.5)
        bus.session.put("bot1/cmd_vel", b"\x00\x01not a twist")  # rejected and counted; it moves nothing
        # Nothing to wait on for a step that must not come: the simulator repeats its poses every 0.1 s,
        # so two seconds of repeats all at instant 0 show it waited for agent 1.
        assert not wait_for(lambda: bus.stamped(PERIOD_NS), 2.0 / limit(1.0))
        bus.command(1, 0.0)
        assert wait_for(lambda: bus.stamped(PERIOD_NS), 30)
        assert bus.newest(0)[1] > start[1] - 1.0  # (decoded and in the map frame)
        tokens[1].undeclare()  # agent 1 left: its base stands, and the world no longer waits for it
        stranger.undeclare()
        bus.command(0, 0.5)
        assert wait_for(lambda: bus.stamped(2 * PERIOD_NS), 30)
        assert not bus.stamped(3 * PERIOD_NS)  # one command, one step
        process.send_signal(signal.SIGTERM)
        assert process.wait(timeout=limit(30)) == EXIT_SIGTERM
    figures = json.loads((bus.out / "sim.json").read_text())
    assert figures["simulated_steps"] == 2 and figures["physical_contacts"] == 0
    assert figures["commands_received"] == 3 and figures["commands_rejected"] == 1
    rows = (bus.out / "sim-truth.csv").read_text().splitlines()
    assert rows[0] == "t,agent,x,y,theta" and len(rows) == 1 + 3 * 2  # instants 0, 0.1, 0.2; two bases
    x = [float(row.split(",")[2]) for row in rows[1:] if row.split(",")[1] == "0"]
    assert x[0] != x[2]  # agent 0's base moved (its heading is the seeded one, so not necessarily along x)


def test_in_realtime_the_world_steps_on_the_wall_clock_and_a_silent_base_stops_on_its_own(tmp_path):
    with simulator(tmp_path, "realtime", "--speed", "1", "--command-timeout", "0.3") as (bus, process):
        assert wait_for(lambda: bus.stamped(5 * PERIOD_NS), 60)  # no agent, no command: it steps all the same
        before = bus.newest(0)
        bus.command(0, 0.5)
        assert wait_for(lambda: bus.stamped(before[0] + 20 * PERIOD_NS), 30)  # 2 s on
        stopped_at = bus.newest(0)
        assert stopped_at[1:] != pytest.approx(before[1:], abs=0.05)  # it drove, for about 0.3 s at 0.5 m/s
        assert wait_for(lambda: bus.stamped(stopped_at[0] + 10 * PERIOD_NS), 30)
        later = bus.newest(0)
        assert later[1:] == pytest.approx(stopped_at[1:], abs=1e-3)  # 0.3 s without a command: it stood still
        process.send_signal(signal.SIGTERM)
        assert process.wait(timeout=limit(30)) == EXIT_SIGTERM
    assert json.loads((bus.out / "sim.json").read_text())["simulated_steps"] >= 35


def test_a_scenario_without_physics_is_refused_naming_the_key(tmp_path):
    config = tmp_path / "kinematic.toml"
    config.write_text(ROOM.replace('physics = "mujoco"\n', ""))
    refused = anicov("sim", "--config", str(config), "--connect", f"tcp/127.0.0.1:{free_port()}", timeout=120)
    assert refused.returncode == 2 and "scenario key 'physics'" in refused.stderr and '"mujoco"' in refused.stderr
