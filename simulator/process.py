"""The simulator process (``anicov sim``, issue 37 item 1): a thin shell around :class:`simulator.bases.SimulatedBases`.

It plays every robot's ROS 2 base on the bus with the keys and messages of the stand-in bases
(deploy/ros2/test_base.py) and of zenoh-bridge-ros2dds: ``<namespace>/cmd_vel`` (Twist) in,
``<namespace>/odom`` (Odometry) and, with a ``[noise]`` localiser, ``<namespace>/amcl_pose``
(PoseWithCovarianceStamped) out. The agents drive it with ``--robot ros2``, exactly as they drive real bases.

- **lockstep**: the world steps when every live agent's command of the step is in (an agent that left, its
  liveliness token gone, has its base stand still), then publishes the poses of the next instant; the agents'
  driver (``--ros-sim-time``) waits for them. Until then it repeats the latest poses, for an agent that comes up late.
- **realtime**: the world steps every control period of wall clock (``dt / --speed``) with each base's latest
  command; a base that heard nothing for ``--command-timeout`` seconds stops, as a real base does.

A malformed command is rejected, logged and counted; it never moves a base. When the coordinator declares the
run over (its ``done`` or ``abort`` on the run's control key) the truth's map stops taking what the cameras
see, so ``true_coverage`` is the truth at the declared completion: in lockstep after the team's last step
(the world's step k is the team's), in realtime when the message arrives. At the end (SIGTERM, Ctrl-C) it writes
``sim.json`` (contacts, the truth's coverage, counters) and ``sim-truth.csv`` (the true poses, map frame).
"""

from __future__ import annotations

import json
import logging
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import zenoh

from model.scenario import Scenario
from protocol.decoding import decode
from protocol.keys import TeamKeys, agent_of_key
from protocol.messages import Limits, ProtocolError, RunControl
from protocol.ros2.messages import BadRosMessage, decode_velocity, encode_pose
from protocol.ros2.options import ODOMETRY, POSE_WITH_COVARIANCE, TWIST
from protocol.ros2.transport import bridge_key
from protocol.session import open_session
from runtime.lifecycle import EXIT_OK, StopFlag
from runtime.rundir import step_time
from simulator.bases import Reading, SimulatedBases

log = logging.getLogger("anicov.sim")

REPEAT_PERIOD = 0.1
"""Lockstep: wall seconds between repeats of the latest poses while the world waits for commands."""


@dataclass(frozen=True)
class SimOptions:
    team: str
    clock: str
    speed: float
    namespace_prefix: str = "bot"
    localiser_topic: str = "amcl_pose"
    command_timeout: float = 0.5
    out: str | None = None

    def namespace(self, agent: int) -> str:
        return f"{self.namespace_prefix}{agent}"


class CommandInbox:
    """Each base's latest command, whether one came since the world last stepped, and when (Zenoh's threads
    write, the stepping loop reads)."""

    def __init__(self, agents: int) -> None:
        self.agents = agents
        self.latest = [(0.0, 0.0)] * agents
        self.fresh = [False] * agents
        self.received_at = [-float("inf")] * agents
        self.counters = {"commands_received": 0, "commands_rejected": 0}
        self.changed = threading.Condition()

    def on_command(self, agent: int, sample: zenoh.Sample) -> None:
        try:
            command = decode_velocity(sample.payload.to_bytes(), TWIST)
        except BadRosMessage as error:
            with self.changed:
                self.counters["commands_rejected"] += 1
                rejected = self.counters["commands_rejected"]
            if rejected == 1 or rejected % 100 == 0:
                log.warning(
                    "base %d: rejected a command on %s (%d so far): %s", agent, sample.key_expr, rejected, error
                )
            return
        with self.changed:
            self.latest[agent], self.fresh[agent] = command, True
            self.received_at[agent] = time.monotonic()
            self.counters["commands_received"] += 1
            self.changed.notify_all()

    def all_in(self, agents: set[int]) -> bool:
        """Every one of ``agents`` sent a command since the last step (and there is at least one)."""
        return bool(agents) and all(self.fresh[agent] for agent in agents)

    def take(self, live: set[int] | None, timeout: float) -> list[tuple[float, float]]:
        """The commands for this step: each base's latest; zero for a base that is not ``live`` (lockstep) or
        heard nothing for ``timeout`` seconds (realtime: ``live`` None). Marks them all used."""
        now = time.monotonic()
        commands = []
        for agent, command in enumerate(self.latest):
            stands = (agent not in live) if live is not None else now - self.received_at[agent] > timeout
            commands.append((0.0, 0.0) if stands else command)
            self.fresh[agent] = False
        return commands


class TeamWatch:
    """Which agents are alive (their liveliness tokens) and whether the coordinator declared the run over."""

    def __init__(self, scenario: Scenario, inbox: CommandInbox) -> None:
        self.limits, self.inbox = Limits.of(scenario), inbox
        self.live: set[int] = set()
        self.seen_agents = False
        self.steps: int | None = None  # the team's steps when the coordinator declared the run over

    @property
    def over(self) -> bool:
        """The coordinator declared the run over (done or abort)."""
        return self.steps is not None

    @property
    def ended(self) -> bool:
        """The run was declared over and every agent has left: nothing will command a base again."""
        return self.over and self.seen_agents and not self.live

    def all_in(self, step: int) -> bool:
        """Every live agent's command of the step is in (under the inbox's lock). The first step also waits until
        the whole team is live, as the coordinator's first go does: an agent whose token reached us after a
        teammate's first command must not have its base left standing at step 0."""
        return (step > 0 or len(self.live) >= self.inbox.agents) and self.inbox.all_in(self.live)

    def on_liveliness(self, sample: zenoh.Sample) -> None:
        agent = agent_of_key(f"{sample.key_expr}")
        if agent is None or agent >= self.inbox.agents:  # not one of this scenario's robots: no base to play
            return
        with self.inbox.changed:
            (self.live.add if sample.kind == zenoh.SampleKind.PUT else self.live.discard)(agent)
            self.seen_agents = True
            self.inbox.changed.notify_all()

    def on_control(self, sample: zenoh.Sample) -> None:
        try:
            message = decode(sample.payload.to_bytes(), self.limits, expected="control")
        except ProtocolError:
            return  # not ours to count: the coordinator's own readers reject and count it
        if isinstance(message, RunControl) and message.kind in ("done", "abort") and not self.over:
            with self.inbox.changed:
                self.steps = message.step
                self.inbox.changed.notify_all()
            log.info("the run is over (%s at step %d): the truth's map stops here", message.kind, message.step)


class Publishers:
    """Each base's odometry publisher and, with a localiser, its fixes' publisher."""

    def __init__(self, session: zenoh.Session, options: SimOptions, bases: SimulatedBases) -> None:
        # Lockstep: a lost pose or fix would change what a robot believes, and so the run; none may be dropped.
        # Realtime: a late pose is worth less than the next, as on a robot.
        congestion = zenoh.CongestionControl.BLOCK if options.clock == "lockstep" else zenoh.CongestionControl.DROP

        def publisher(agent: int, topic: str) -> zenoh.Publisher:
            return session.declare_publisher(bridge_key(options.namespace(agent), topic), congestion_control=congestion)

        self.odometry = [publisher(i, "odom") for i in range(bases.agents)]
        self.fixes = [publisher(i, options.localiser_topic) for i in range(bases.agents) if bases.localiser]
        noise = bases.noise
        self.sigma = (noise.localiser_sigma * bases.scenario.metres_per_unit, noise.localiser_heading)

    def publish(self, readings: list[Reading]) -> None:
        """A base's fixes go before its odometry: the driver pairs a fix with the odometry of its stamp, and
        the step's pose must already hold the fixes that arrived with it."""
        for reading in readings:
            for stamp, pose in reading.fixes:
                # The start pose is exact, as an operator gives AMCL its initial pose: no covariance (ROS's
                # "unknown"), which the driver takes with no doubt, as the in-process belief starts; every time it is
                # sent again for a driver that came up late.
                sigma = (0.0, 0.0) if reading.start else self.sigma
                self.fixes[reading.agent].put(encode_pose(POSE_WITH_COVARIANCE, pose, stamp, "map", sigma=sigma))
            self.odometry[reading.agent].put(
                encode_pose(ODOMETRY, reading.odometry, reading.stamp_ns, "odom", velocity=reading.velocity)
            )


def run_simulator(scenario: Scenario, options: SimOptions, config: zenoh.Config, stop: StopFlag) -> int:
    bases = SimulatedBases(scenario)
    inbox = CommandInbox(bases.agents)
    watch = TeamWatch(scenario, inbox)
    keys = TeamKeys(options.team)
    with open_session(config) as session:
        for agent in range(bases.agents):
            key = bridge_key(options.namespace(agent), "cmd_vel")
            session.declare_subscriber(key, lambda sample, agent=agent: inbox.on_command(agent, sample))
        session.liveliness().declare_subscriber(keys.alive_agents, watch.on_liveliness, history=True)
        session.declare_subscriber(keys.control, watch.on_control)
        publishers = Publishers(session, options, bases)
        log.info(
            "simulating %d bases (%s clock) on %s..%s", bases.agents, options.clock,
            bridge_key(options.namespace(0), "cmd_vel"), bridge_key(options.namespace(bases.agents - 1), "odom"),
        )  # fmt: skip
        publishers.publish(bases.readings())
        if options.clock == "lockstep":
            step_in_lockstep(bases, inbox, watch, publishers, stop)
        else:
            step_in_realtime(
                bases, inbox, watch, publishers, stop, scenario.dt / options.speed, options.command_timeout
            )
    write_outputs(bases, inbox, options)
    return stop.exit_code(EXIT_OK)


def step_in_lockstep(
    bases: SimulatedBases, inbox: CommandInbox, watch: TeamWatch, publishers: Publishers, stop: StopFlag
) -> None:
    """Step when every live agent's command is in; meanwhile repeat the latest poses now and then."""
    latest = bases.readings()
    while not stop.stopped and not watch.ended:
        with inbox.changed:
            ready = inbox.changed.wait_for(
                lambda: watch.all_in(bases.step) or stop.stopped or watch.ended, timeout=REPEAT_PERIOD
            )
            ready = ready and watch.all_in(bases.step)
            commands = inbox.take(set(watch.live), 0.0) if ready else None
        if commands is None:  # the fixes too: a late driver needs the first to place its odometry in the map
            publishers.publish(latest)
            continue
        for agent, (linear, angular) in enumerate(commands):
            bases.command(agent, linear, angular)
        # The world's step k is the team's step k: the truth senses the steps the team took, however late
        # the coordinator's done overtakes a command on its way here.
        bases.sensing = watch.steps is None or bases.step < watch.steps
        latest = bases.advance()
        publishers.publish(latest)


def step_in_realtime(
    bases: SimulatedBases,
    inbox: CommandInbox,
    watch: TeamWatch,
    publishers: Publishers,
    stop: StopFlag,
    period: float,
    command_timeout: float,
) -> None:
    """Step every ``period`` wall seconds with each base's latest command."""
    next_step = time.monotonic() + period
    while not stop.wait(max(0.0, next_step - time.monotonic())) and not watch.ended:
        with inbox.changed:
            commands = inbox.take(None, command_timeout)
        for agent, (linear, angular) in enumerate(commands):
            bases.command(agent, linear, angular)
        bases.sensing = not watch.over
        publishers.publish(bases.advance())
        next_step += period
        if next_step < time.monotonic() - period:  # far behind (a paused machine): do not race to catch up
            next_step = time.monotonic()


def write_outputs(bases: SimulatedBases, inbox: CommandInbox, options: SimOptions) -> None:
    """sim.json and sim-truth.csv in ``options.out`` (nothing without it); the figures in the log either way."""
    figures = bases.figures() | inbox.counters
    log.info("simulator: %s", ", ".join(f"{key} {value}" for key, value in figures.items()))
    if options.out is None:
        return
    out = Path(options.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "sim.json").write_text(json.dumps(figures, indent=2) + "\n", encoding="utf-8")
    scenario, frame = bases.scenario, bases.frame
    lines = ["t,agent,x,y,theta"]
    for step, poses in enumerate(bases.team.true_poses):
        t = repr(step_time(step, scenario.dt))
        for agent, pose in enumerate(poses.tolist()):
            x, y, theta = frame.pose_to_map(tuple(pose))
            lines.append(f"{t},{agent},{x!r},{y!r},{theta!r}")
    (out / "sim-truth.csv").write_text("\n".join(lines) + "\n", encoding="ascii")
