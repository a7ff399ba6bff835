"""Agents driving ROS 2 bases over Zenoh, end to end: real processes, real sessions on loopback, and
stand-in bases (deploy/ros2/test_base.py: rosbags and zenoh only, no code of the driver) that integrate
the unicycle, publish odometry at 30 Hz on bridge-style keys and stop on their own command timeout."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from datetime import datetime
from pathlib import Path

import pytest

from tests.teamrun import (
    ROOT,
    anicov,
    check_realtime_run,
    free_port,
    launcher_command,
    limit,
    processes_of,
    run,
    unique_team,
    wait_for,
)
from tests.teamrun import write_scenario as write_toml

TEST_BASE = ROOT / "deploy" / "ros2" / "test_base.py"
POSE_TIMEOUT = 0.5  # the driver's default --ros-pose-timeout, seconds
COMMAND_TIMEOUT = 0.5  # the stand-in base's default --command-timeout, seconds
BASE_TICK = 1 / 30  # the stand-in base's period, seconds
CONTROL_PERIOD = 0.025  # dt 0.5 x seconds_per_unit 0.05: one command every 25 ms
SLACK = 0.3  # scheduling on a loaded 2-core machine: what a stated time may be late by, seconds
A_SECOND_OF_CONTROL = 40  # commands: what the control loop sends in a second, however long a busy machine takes


@pytest.mark.slow  # 30 s of real time, the suite's longest ROS 2 test: outside the default suite (its 10-minute
# budget was reached, 609 s at 2026-12-07); the default suite keeps ROS 2 bases driven in realtime (the tests below)
# and a ROS 2 team to completion (the simulator's, lockstep). Run with -m slow.
def test_three_agents_drive_three_ros2_bases_to_complete_coverage(tmp_path):
    """The paper's scenario scaled (scenarios/ros2-paper.toml: 1 m/s, 40 Hz control) in a 3.5 m room (70 x 70
    units instead of the file's 100 x 100: 18 s of driving instead of 36)."""
    shipped = (ROOT / "scenarios" / "ros2-paper.toml").read_text()
    assert "domain = [100.0, 100.0]" in shipped
    config = str(tmp_path / "ros2-room.toml")
    Path(config).write_text(shipped.replace("domain = [100.0, 100.0]", "domain = [70.0, 70.0]"))
    engine = anicov(
        "run", "--config", config, "--seed", "0", "--out", str(tmp_path / "engine"), "--quiet", "--no-record"
    )
    assert engine.returncode == 0, engine.stderr
    out = tmp_path / "team"
    launched = run(
        launcher_command(
            "--config", config, "--seed", "0", "--robot", "ros2", "--test-bases", "--clock", "realtime",
            "--out", str(out),
        ),
        timeout=300,
    )  # fmt: skip
    assert launched.returncode == 0, launched.stderr + launched.stdout
    summary = check_realtime_run(
        out, k_v=1.0, k_omega=1.0, dt=0.5, simulated=False
    )  # a simulated run's checks but eq. 1 (measured poses)
    reference = json.loads((tmp_path / "engine" / "summary.json").read_text())["completion_time"]
    ratio = summary["completion_time"] / reference
    (tmp_path / "ratio.txt").write_text(f"{ratio:.3f}\n")
    # Measured here: 1.03, 1.04, 1.11 in the 100 x 100 room, 1.02, 1.02 in this one, 1.17 in a 60 x 60 one
    # (odometry at 30 Hz lags the 40 Hz control and the start weighs more in a short run; the simulated
    # realtime team keeps within 15 %, this one within 25 %).
    assert 0.85 <= ratio <= 1.25, ratio
    assert (out / "recording.rrd").stat().st_size > 0
    for agent in range(3):
        events = read_base_log(out / "logs" / f"base-{agent}.jsonl")
        commands = [event for event in events if event["event"] == "command"]
        counts = json.loads((out / "logs" / f"agent-{agent}.counts.json").read_text())
        # Every step the agent took sent a Twist, and the Twists sent reached the base but for the few that the
        # command publisher drops under congestion (Zenoh's default for it, DROP: a late command is
        # worth less than the next one; the stops go reliably). Not the team's step count: on a loaded
        # machine an agent's 40 Hz tick may come too late for a step (a fresh clone's CI run under
        # pytest-xdist, 2026-12-06: 712 Twists for the team's 734 steps), which is the clock's business. Dropped,
        # measured: none on a quiet machine, 2 of 756 with a study sharing the two cores.
        assert counts["robot"]["commands_sent"] >= counts["steps"] > 0
        assert 0.98 * counts["robot"]["commands_sent"] <= len(commands) <= counts["robot"]["commands_sent"]
        assert (commands[-1]["v"], commands[-1]["omega"]) == (0.0, 0.0)  # left standing still
        assert counts["rejected"] == 0 and counts["robot"]["poses_rejected"] == 0


# ------------------------------------------------------------------ faults


def read_base_log(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def agent_log_time(log: Path, text: str, after: float = 0.0) -> float | None:
    """The wall time of the first line of an agent's log holding ``text`` logged after ``after``."""
    for line in log.read_text().splitlines():
        if text in line:
            stamp = datetime.strptime(line[:23], "%Y-%m-%d %H:%M:%S,%f").timestamp()
            if stamp >= after - 0.001:
                return stamp
    return None


class RosTeam:
    """A team router, a robot-side router (as zenoh-bridge-ros2dds on the robot), a stand-in base on it,
    the coordinator, agent 0 driving the base (--ros-connect to the robot's router) and agent 1 on a
    simulated unicycle, so that the run goes on while agent 0 is away."""

    def __init__(self, tmp_path: Path, stack: ExitStack, secure: bool = False) -> None:
        self.dir, self.stack = tmp_path, stack
        self.team, self.router_port, self.robot_port = unique_team(), free_port(), free_port()
        self.profile = None
        if secure:  # the team's bus as deploy/README.md's secure profile has it; the robot's side as before
            from anicov.secure import make_profile

            endpoint = f"tls/127.0.0.1:{self.router_port}"
            self.profile = make_profile(tmp_path / "secure", agents=2, team=self.team, endpoint=endpoint)
        self.base_log = tmp_path / "base.jsonl"
        # Four times the paper's area: the run lasts long past the faults below.
        self.config = write_toml(
            tmp_path / "scenario.toml",
            domain=[200.0, 200.0], dt=0.5, agents=2, seed=1, metres_per_unit=0.05, seconds_per_unit=0.05,
        )  # fmt: skip
        self.processes: dict[str, subprocess.Popen] = {}
        self.restarts = 0

    def start(self, name: str, command: list[str]) -> subprocess.Popen:
        log = open(self.dir / f"{name}.log", "ab")
        self.stack.callback(log.close)
        process = subprocess.Popen(command, cwd=ROOT, stdout=log, stderr=subprocess.STDOUT)
        self.stack.callback(lambda: (process.poll() is None and process.kill(), process.wait()))
        self.processes[name] = process
        return process

    def router(self, name: str, port: int, secure: bool = False) -> None:
        where = ["--zenoh-config", str(self.profile.config("router"))] if secure and self.profile else []
        where = where or ["--listen", f"tcp/127.0.0.1:{port}"]
        self.start(name, [sys.executable, "-m", "anicov.cli", "router", *where])

    def team_flags(self, role: str) -> list[str]:
        flags = ["--team", self.team, "--config", str(self.config), "--clock", "realtime", "--speed", "20"]
        if self.profile:
            return [*flags, "--zenoh-config", str(self.profile.config(role))]
        return [*flags, "--connect", f"tcp/127.0.0.1:{self.router_port}"]

    def agent(self, name: str = "agent-0") -> subprocess.Popen:
        ros = ["--robot", "ros2", "--ros-namespace", "bot0", "--ros-connect", f"tcp/127.0.0.1:{self.robot_port}"]
        command = [sys.executable, "-m", "anicov.cli", "agent", "--id", "0", *self.team_flags("agent-0"), *ros]
        return self.start(name, command)

    def launch(self) -> None:
        from model.parameters import starting_poses
        from model.scenario import load_scenario

        self.router("router", self.router_port, secure=True)
        self.router("robot-router", self.robot_port)
        x, y, theta = starting_poses(load_scenario(self.config))[0]
        pose = [repr(float(x * 0.05)), repr(float(y * 0.05)), repr(float(theta * 180 / 3.141592653589793))]
        self.start(
            "base",
            [sys.executable, str(TEST_BASE), "--connect", f"tcp/127.0.0.1:{self.robot_port}", "--namespace", "bot0",
             "--pose", *pose, "--log", str(self.base_log)],
        )  # fmt: skip
        cli = [sys.executable, "-m", "anicov.cli"]
        self.start(
            "coordinator", [*cli, "coordinator", *self.team_flags("coordinator"), "--out", str(self.dir / "run")]
        )
        self.start("agent-1", [*cli, "agent", "--id", "1", *self.team_flags("agent-1")])
        self.agent()
        assert self.wait_until_moving(after=0.0, timeout=90), (self.dir / "agent-0.log").read_text()

    def events(self) -> list[dict]:
        return read_base_log(self.base_log) if self.base_log.exists() else []

    def commands_after(self, moment: float) -> list[dict]:
        return [e for e in self.events() if e["event"] == "command" and e["t"] >= moment]

    def wait_until_moving(self, after: float, timeout: float = 60, commands: int = 1) -> bool:
        """Until the base has had ``commands`` moving commands after ``after`` (``timeout``: an outer limit)."""
        return wait_for(lambda: len(self.moving_after(after)) >= commands, timeout=timeout)

    def moving_after(self, moment: float) -> list[dict]:
        return [c for c in self.commands_after(moment) if abs(c["v"]) > 0 or abs(c["omega"]) > 0]

    def zeros_after(self, moment: float) -> list[dict]:
        return [c for c in self.commands_after(moment) if (c["v"], c["omega"]) == (0.0, 0.0)]

    def timeout_stop_after(self, moment: float) -> dict | None:
        return next((e for e in self.events() if e["event"] == "timeout-stop" and e["t"] >= moment), None)


@contextmanager
def ros_team(tmp_path: Path, secure: bool = False) -> Iterator[RosTeam]:
    with ExitStack() as stack:
        team = RosTeam(tmp_path, stack, secure)
        team.launch()
        yield team


def test_a_ros2_agent_in_a_secure_team_reaches_its_base_on_the_robots_own_bridge(tmp_path):
    """deploy/ros2.md's layout: the team's bus under the secure profile as today (mutual TLS, access
    control: agent-0 may publish only its own keys), the robot's topics on the robot's own router."""
    with ros_team(tmp_path, secure=True) as team:
        assert team.wait_until_moving(after=0.0)
        assert agent_log_time(tmp_path / "agent-0.log", "agent 0 starts (realtime clock)") is not None
        assert "tls/" in (tmp_path / "secure" / "agent-0.json5").read_text()


def test_sigterm_of_the_agent_sends_zero_and_sigkill_leaves_the_base_to_its_own_timeout(tmp_path):
    with ros_team(tmp_path) as team:
        sent = time.time()
        team.processes["agent-0"].send_signal(signal.SIGTERM)
        assert team.processes["agent-0"].wait(timeout=limit(60)) == 143
        # The base logs what it receives as it comes: the agent's last command may still be on its way.
        assert wait_for(lambda: team.zeros_after(sent), timeout=60), team.commands_after(sent)
        last = team.commands_after(0.0)[-1]
        # The zero goes out from the control loop's own thread within a period of the signal.
        assert (last["v"], last["omega"]) == (0.0, 0.0)
        first_zero = team.zeros_after(sent)[0]
        assert first_zero["t"] - sent <= CONTROL_PERIOD + SLACK, first_zero["t"] - sent
        assert team.timeout_stop_after(sent) is None or team.timeout_stop_after(sent)["v"] == 0.0

        # Started again, it resumes from the coordinator's snapshot, waits for its pose and drives on.
        restarted = time.time()
        team.agent("agent-0.restart")
        # It drives on: half a second of commands (not of a busy machine's wall clock) before the kill.
        driving = team.wait_until_moving(after=restarted, commands=A_SECOND_OF_CONTROL // 2)
        assert driving, (tmp_path / "agent-0.restart.log").read_text()
        killed = time.time()
        team.processes["agent-0.restart"].kill()  # no chance to send anything
        assert wait_for(lambda: team.timeout_stop_after(killed) is not None, timeout=60)
        stop = team.timeout_stop_after(killed)
        assert abs(stop["v"]) + abs(stop["omega"]) > 0  # it was moving (or turning): its own watchdog stopped it
        assert stop["t"] - killed <= COMMAND_TIMEOUT + BASE_TICK + SLACK, stop["t"] - killed


def test_a_stale_pose_stops_the_robot_and_a_lost_router_moves_it_only_after_a_fresh_pose(tmp_path):
    with ros_team(tmp_path) as team:
        base, agent_log = team.processes["base"], tmp_path / "agent-0.log"
        off = time.time()
        base.send_signal(signal.SIGUSR1)  # its odometry stops (a localiser that died)
        # The agent sees the pose go stale, and the base gets zeros: then a second of control goes by.
        assert wait_for(lambda: agent_log_time(agent_log, "no pose on bot0/odom", after=off) is not None, timeout=60)
        assert wait_for(lambda: team.zeros_after(off), timeout=60), "no zero command after the pose went stale"
        zeros = team.zeros_after(off)
        assert wait_for(lambda: len(team.commands_after(zeros[0]["t"])) > A_SECOND_OF_CONTROL, timeout=60)
        assert zeros[0]["t"] - off <= POSE_TIMEOUT + CONTROL_PERIOD + SLACK, zeros[0]["t"] - off
        assert all((c["v"], c["omega"]) == (0.0, 0.0) for c in team.commands_after(zeros[0]["t"]))
        on = time.time()
        base.send_signal(signal.SIGUSR1)
        assert team.wait_until_moving(after=on)
        assert agent_log_time(agent_log, "a fresh pose on bot0/odom", after=on) is not None

        killed = time.time()
        team.processes["robot-router"].kill()  # the link to the robot is gone: no zero can reach it
        assert wait_for(lambda: team.timeout_stop_after(killed) is not None, timeout=60)
        stop = team.timeout_stop_after(killed)
        assert abs(stop["v"]) > 0 and stop["t"] - killed <= COMMAND_TIMEOUT + BASE_TICK + SLACK
        # The router comes back once the agent has seen its pose go stale without it.
        assert wait_for(lambda: agent_log_time(agent_log, "no pose on bot0/odom", after=killed) is not None, timeout=60)
        back = time.time()
        team.router("robot-router.back", team.robot_port)
        assert team.wait_until_moving(after=back), agent_log.read_text()[-2000:]
        fresh = agent_log_time(agent_log, "a fresh pose on bot0/odom", after=killed)
        assert fresh is not None, agent_log.read_text()[-2000:]
        # Whatever reached the base after the router came back and before the fresh pose was a zero.
        moving = team.moving_after(back)
        assert moving[0]["t"] >= fresh - 0.002, (moving[0]["t"], fresh)


SIM_ROOMS = """domain = [12.0, 8.0]
cell = 1.0
range = 4.0
robot_radius = 0.3
occlusion = true
agents = 2
seed = 3
controller = "anicov"
physics = "mujoco"
obstacles = [[[6.0, 0.0], [7.0, 0.0], [7.0, 2.0], [6.0, 2.0]], [[6.0, 5.0], [7.0, 5.0], [7.0, 8.0], [6.0, 8.0]]]

[noise]
odometry_per_metre = 0.01
odometry_per_radian = 0.01
localiser_sigma = 0.05
localiser_heading_deg = 2.0
localiser_rate = 10.0
localiser_latency = 0.1
command_latency = 0.1
"""
"""Two rooms and a door 3 wide, two robots with bodies and the filter, the issue's noise (issue 37). The door is
crossed: with a door 2 wide the far room was unreachable (no cell's centre in the door holds the disk and its
clearance, r + s + the planning margin > 0.5), with or without the clearance reserve."""


def test_agents_drive_the_simulators_bases_in_lockstep_to_complete_coverage_in_truth(tmp_path):
    """launch_team.py --robot ros2 --sim-bases: anicov sim plays both bases in the physics world; the agents read
    its odometry and its localiser's fixes (amcl_pose) as they would a real robot's, on the team's clock."""
    config = tmp_path / "rooms.toml"
    config.write_text(SIM_ROOMS)
    out, team = tmp_path / "team", unique_team()
    launched = run(
        launcher_command("--config", str(config), "--robot", "ros2", "--sim-bases", "--out", str(out), team=team),
        timeout=300,
    )
    assert launched.returncode == 0, launched.stderr + launched.stdout
    assert "launch_team (lockstep" in launched.stdout and "anicov sim" in launched.stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["completed"] and summary["physical_contacts"] == 0
    assert summary["true_coverage"] >= 0.995  # the goal at declared completion, with the cover margin
    assert summary["simulated_steps"] == summary["steps"]  # lockstep: the world stepped once per team step
    assert summary["commands_rejected"] == 0 and summary["commands_received"] == 2 * summary["steps"]
    for agent in range(2):
        robot = json.loads((out / "logs" / f"agent-{agent}.counts.json").read_text())["robot"]
        assert robot["localiser_poses"] > summary["steps"] // 2 and robot["stale_spells"] == 0
    rows = (out / "sim-truth.csv").read_text().splitlines()
    assert len(rows) == 1 + 2 * (summary["steps"] + 1)
    assert (out / "recording.rrd").stat().st_size > 0
    assert wait_for(lambda: not processes_of(team), 30), processes_of(team)


def test_physics_over_the_bus_needs_the_simulators_bases_and_they_need_physics(tmp_path):
    physical = tmp_path / "physical.toml"
    physical.write_text(SIM_ROOMS)
    refused = run(launcher_command("--config", str(physical), "--out", str(tmp_path / "a")), timeout=120)
    assert refused.returncode == 2 and "scenario key 'physics'" in refused.stderr and "--sim-bases" in refused.stderr
    kinematic = tmp_path / "kinematic.toml"
    kinematic.write_text(SIM_ROOMS.split("physics = ")[0])
    refused = run(
        launcher_command("--config", str(kinematic), "--robot", "ros2", "--sim-bases", "--out", str(tmp_path / "b")),
        timeout=120,
    )
    assert refused.returncode == 2 and "--sim-bases" in refused.stderr and '"mujoco"' in refused.stderr
