"""The agent process: one robot of the team, on the bus.

It keeps its own replica of the coverage map, decides (v, ω) with the same
functions as the in-process engine (:mod:`model.step`), commands its robot,
and publishes its step (coverage delta and state, one message) every step.
It applies its teammates' deltas and follows the coordinator's objectives.

Clocks:

- ``lockstep``: step k starts when the coordinator's go for step k arrives.
  The go carries every member's step k−1 delta (and, on a replanning step,
  the new objectives), so the replica then holds exactly the engine's Λ_k:
  every agent sees full coverage at the same step, and the run equals the
  in-process engine bit for bit. One message in and one out per agent-step.
- ``realtime``: one step every dt/speed seconds of wall-clock time, with
  whatever has arrived by then; never waits for anyone. Lost deltas are
  fetched from the sender's history (gaps, and at the end of the run).
"""

from __future__ import annotations

import logging
import math
import os
import time
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING

import zenoh

from agents.node import AgentNode, AgentOptions
from model.scenario import Scenario
from protocol.agreement import (
    ScenarioMismatch,
    check_agreement,
    check_peers,
    coordinator_digest,
    digest_of,
    peer_digests,
    serve_digest,
)
from protocol.messages import AgentState, AgentStep, MapDelta, encode
from protocol.recovery import END_ONLY, GAP_CHECK_PERIOD, History, LossTimer, fetch, fetch_snapshot, fill_gaps
from protocol.session import RouterUnreachable, logger_listens, open_session, team_publisher, zenoh_config
from protocol.settling import STOPPED, EndBarrier, settle
from protocol.sync import SYNC_PERIOD, SyncServer, sync_with
from protocol.traffic import TrafficReporter
from runtime.lifecycle import EXIT_FAILED, EXIT_OK, EXIT_USAGE, StopFlag, parent_is_gone, settle_garbage_collector
from runtime.rundir import write_counts

if TYPE_CHECKING:
    from agents.ros2.driver import Ros2Robot
    from protocol.ros2.options import Ros2Options

log = logging.getLogger("anicov.agent")

HELLO_PERIOD = 0.2
"""Seconds between repeated hellos until the coordinator's first go arrives."""


def run_agent(
    scenario: Scenario, options: AgentOptions, config: zenoh.Config, stop: StopFlag, ros2: Ros2Options | None = None
) -> int:
    parent = os.getppid()
    with open_session(config) as session, robot_of(session, scenario, options, ros2) as robot:
        if robot is not None and not robot.wait_for_pose(lambda: stop.stopped, lambda: parent_is_gone(parent)):
            return stop.exit_code(EXIT_FAILED)  # the robot's pose never came: nothing was commanded
        node = AgentNode(scenario, options, robot)
        code = run_on_bus(session, node, stop, parent)
    write_counts(options.counts_file, node.counts() | ({"robot": robot.counts()} if robot is not None else {}))
    return code


@contextmanager
def robot_of(
    session: zenoh.Session, scenario: Scenario, options: AgentOptions, ros2: Ros2Options | None
) -> Iterator[Ros2Robot | None]:
    """The ROS 2 base (None: the simulated unicycle, made by the node). However the block ends (end of
    run, signal, exception) the base is sent zero before the sessions close."""
    if ros2 is None:
        yield None
        return
    from agents.ros2.driver import Ros2Robot

    with ExitStack() as stack:
        robot_session = session
        if ros2.connect:  # the robot's own bridge or router
            where = ", ".join(ros2.connect)
            log.info("agent %d connects to its robot's bridge or router at %s", options.agent, where)
            try:
                robot_session = stack.enter_context(open_session(zenoh_config("client", connect=list(ros2.connect))))
            except RouterUnreachable as error:
                raise RouterUnreachable(f"the robot's bridge or router at {where}: {error}") from error
        robot = Ros2Robot(robot_session, ros2, scenario, options.agent)
        stack.callback(robot.close)
        yield robot


def run_on_bus(session: zenoh.Session, node: AgentNode, stop: StopFlag, parent: int) -> int:
    """Join the team, step until the run ends, stop the robot and finish the run."""
    options = node.options
    lockstep = options.clock == "lockstep"
    bus = declare_endpoints(session, node, lockstep)
    traffic = TrafficReporter(session, node.keys.traffic("agent", options.agent), "agent", options.agent, bus.traffic)
    try:
        agreed = wait_for_peers(bus, stop, parent) if options.no_coordinator else wait_for_agreement(bus, stop, parent)
        if not agreed:
            bus.token.undeclare()
            return stop.exit_code(EXIT_FAILED) if options.no_coordinator else exit_code(node, stop)
    except ScenarioMismatch as error:
        log.error("agent %d refuses to join: %s", options.agent, error)
        bus.token.undeclare()
        return EXIT_USAGE
    traffic.start()
    if options.no_coordinator:
        start_without_coordinator(bus)
    else:
        if resume_from_snapshot(session, node):
            # Lockstep: it says hello like a new robot, and the coordinator lists it again from its next go.
            node.rejoining = lockstep
            log.info("agent %d resumes from the coordinator's snapshot after step %d", options.agent, node.step - 1)
        wait_until_admitted(bus, stop, parent)
    log.info("agent %d starts (%s clock)", options.agent, options.clock)
    try:
        if lockstep:
            run_lockstep_steps(bus, stop, parent)
        else:
            run_realtime_steps(bus, node.scenario.dt / options.speed, stop, parent)
    except BaseException:
        traffic.stop()  # its thread must not publish on a session about to close
        raise
    finally:
        node.robot.stop()  # before the end-of-run exchanges: a real base must not roll on meanwhile
    finish_run(bus, lockstep, stop)
    traffic.stop()
    node.bytes_served = bus.traffic()[0] - node.bytes_sent
    bus.token.undeclare()
    return exit_code(node, stop)


@dataclass
class Bus:
    """What an agent declared on the team's bus, and the sends and asks it makes through it."""

    session: zenoh.Session
    node: AgentNode
    step_publisher: zenoh.Publisher
    token: zenoh.LivelinessToken
    history: History
    loss: LossTimer  # lockstep: how long a silence means a lost go
    sync: SyncServer | None = None  # comm_range: anti-entropy answers
    barrier: EndBarrier | None = None  # realtime: nobody leaves before every replica is whole

    def traffic(self) -> tuple[int, int]:
        """Payload bytes out (published, and replies to teammates' queries) and in, so far."""
        node = self.node
        served = self.history.bytes_served + node.relay.bytes_served + (self.sync.bytes_served if self.sync else 0)
        return node.bytes_sent + served, node.inbox.bytes_received

    def publish(self, delta: MapDelta, state: AgentState) -> None:
        payload = encode(AgentStep(delta, state))  # one message a step: one send, one delivery each
        self.node.bytes_sent += len(payload)
        self.history.add(state.step, payload)
        self.step_publisher.put(payload)

    def recover_go(self) -> None:
        """A go (or the end of the run) that should be here is not: ask the coordinator's history."""
        fetch(self.session, self.node.keys.go_history, self.node.inbox, first=self.node.step)


def declare_endpoints(session: zenoh.Session, node: AgentNode, lockstep: bool) -> Bus:
    keys, agent = node.keys, node.options.agent
    if lockstep:
        # Teammates' deltas arrive bundled in the coordinator's go: one message a step, not N − 1.
        session.declare_subscriber(keys.go, node.inbox.on_sample)
    else:
        # Remote only: our own deltas are applied when made, an echo would only cost a decode.
        session.declare_subscriber(keys.all_steps, node.inbox.on_sample, allowed_origin=zenoh.Locality.REMOTE)
        session.declare_subscriber(keys.objectives, node.inbox.on_sample)
        session.declare_queryable(keys.agent_relay(agent), node.relay.serve)
    session.declare_subscriber(keys.control, node.inbox.on_sample)
    session.liveliness().declare_subscriber(keys.alive_agents, node.inbox.on_liveliness, history=True)
    step_publisher = team_publisher(session, keys.agent_step(agent))
    token = session.liveliness().declare_token(keys.alive("agent", agent))
    settle_garbage_collector()

    serve_digest(session, keys.agent_scenario(agent), digest_of(node.scenario))  # for a team with no coordinator
    history = History(keys.agent_history(agent), capacity=node.radio.history_steps())
    session.declare_queryable(keys.agent_history(agent), history.serve)
    sync = None
    if not lockstep and math.isfinite(node.scenario.comm_range):
        sync = SyncServer(keys.agent_sync(agent), agent, node.scenario.agents, history, node.relay)
        session.declare_queryable(keys.agent_sync(agent), sync.serve)
    session.declare_queryable(
        keys.agent_snapshot(agent),
        lambda query: query.reply(keys.agent_snapshot(agent), encode(node.replica.snapshot())),
    )
    barrier = None if lockstep else EndBarrier(session, keys, "agent", agent)
    return Bus(session, node, step_publisher, token, history, LossTimer(), sync, barrier)


SNAPSHOT_TRIES = 10
"""Times a starting agent asks the coordinator (known to be there) for its snapshot, 2 s each, before
taking the run as fresh. A busy coordinator on a loaded machine can take over a second to answer."""


def resume_from_snapshot(session: zenoh.Session, node: AgentNode) -> bool:
    """A restarted robot: resume from the coordinator's snapshot, and the relays for the last steps
    that reached teammates but not the coordinator (see AgentNode.load_snapshot). False: a fresh run.
    Called once the coordinator has answered the agreement, so an answer is due: it is asked again
    until one comes (a session just opened may ask before it has heard of the queryable)."""
    snapshot = None
    for _ in range(SNAPSHOT_TRIES):
        snapshot = fetch_snapshot(session, node.keys.snapshot, node.limits, timeout=2.0)
        if snapshot is not None:
            break
    else:
        log.warning("agent %d: the coordinator never answered for its snapshot; starting fresh", node.options.agent)
    first = node.load_snapshot(snapshot) if snapshot is not None else None
    if snapshot is None or first is None:
        return False  # a fresh run: nothing of ours to resume
    fetch(session, node.keys.all_relays, node.inbox, first=first, relayed=node.options.agent)
    node.finish_resume(snapshot.poses.get(node.options.agent))
    return True


def wait_for_agreement(bus: Bus, stop: StopFlag, parent: int) -> bool:
    """Wait until the coordinator says it runs this agent's scenario and map (ScenarioMismatch if not).
    False: stopped, or the launcher is gone, before it answered."""
    node = bus.node
    mine = digest_of(node.scenario)
    while not stop.stopped:
        theirs = coordinator_digest(bus.session, node.keys, node.limits, timeout=HELLO_PERIOD)
        if theirs is not None:
            check_agreement(mine, theirs, node.scenario)
            return True
        if parent_is_gone(parent):
            return False
    return False


PEERS_TIMEOUT = 120.0
"""No coordinator: seconds an agent waits for every teammate to answer before giving up (as a
coordinator waits for every hello)."""


def wait_for_peers(bus: Bus, stop: StopFlag, parent: int) -> bool:
    """No coordinator: wait until every agent of the team answers with this agent's scenario and map
    (ScenarioMismatch at the first that does not) and, with ``await_logger``, a logger listens. False:
    stopped, the launcher gone, or PEERS_TIMEOUT passed (a teammate that died at its start would
    otherwise keep the others waiting for ever)."""
    node = bus.node
    mine = digest_of(node.scenario)
    deadline = time.monotonic() + PEERS_TIMEOUT
    found: dict = {}
    logger_ready = not node.options.await_logger
    while not stop.stopped:
        found = peer_digests(bus.session, node.keys, node.limits, timeout=HELLO_PERIOD)
        check_peers(mine, found, node.scenario)
        # A logger once seen is not asked again: the wait is for a logger to be listening when the run starts.
        logger_ready = logger_ready or logger_listens(bus.session, node.keys.alive("logger"), timeout=HELLO_PERIOD)
        if len(found) == node.scenario.agents and logger_ready:
            return True
        if parent_is_gone(parent):
            return False
        if time.monotonic() > deadline:
            missing = sorted(set(range(node.scenario.agents)) - set(found))
            never = f"agents {missing}" if missing else "no logger"
            log.error("agent %d: %s answered in %.0f s; giving up", node.options.agent, never, PEERS_TIMEOUT)
            return False
    return False


def start_without_coordinator(bus: Bus) -> None:
    """No coordinator: every teammate is there and agrees, so the run starts now. The hello tells the
    teammates (and a logger) where this robot starts; local planning gives it its first objective."""
    node = bus.node
    node.load_kernels()
    bus.step_publisher.put(encode(node.hello()))
    node.started = True
    log.info("agent %d: all %d agents agree; starting without a coordinator", node.options.agent, node.scenario.agents)


def wait_until_admitted(bus: Bus, stop: StopFlag, parent: int) -> None:
    """Wait for the first go, saying hello until the coordinator has heard it."""
    node = bus.node
    next_hello = 0.0
    hellos = 0
    while not node.admitted() and node.finished is None and not stop.stopped:
        if time.monotonic() >= next_hello:
            bus.step_publisher.put(encode(node.hello()))
            next_hello = time.monotonic() + HELLO_PERIOD
            hellos += 1
            if hellos == 1:
                node.load_kernels()  # while the coordinator waits for the others' hellos
            if hellos % 5 == 0 and not node.rejoining:
                bus.recover_go()  # the first go may have been lost
        item = node.inbox.get(timeout=0.05)
        if item is not None:
            node.handle(item)
        if parent_is_gone(parent):
            break


def run_lockstep_steps(bus: Bus, stop: StopFlag, parent: int) -> None:
    """One step each time the coordinator's go for it arrives, until the end of the run."""
    node = bus.node
    while node.finished is None and not stop.stopped and not parent_is_gone(parent):
        wait_for_go(bus, stop)
        if node.finished is not None or stop.stopped:
            break
        bus.publish(*node.control_step())
        bus.loss.step_done()


def wait_for_go(bus: Bus, stop: StopFlag) -> None:
    """Until this step's go is here (or the run ends): after a silence that means loss, ask for it."""
    node, loss = bus.node, bus.loss
    waiting_since = last_news = time.monotonic()
    while not node.ready_for_step() and node.finished is None and not stop.stopped:
        item = node.inbox.get(timeout=loss.patience)
        if item is not None:
            node.handle(item)
            last_news = time.monotonic()
        elif time.monotonic() - last_news >= loss.patience:
            loss.recovering()
            bus.recover_go()
            last_news = time.monotonic()
        if time.monotonic() - waiting_since > 5.0:
            log.info("agent %d still waiting at step %d: %s", node.options.agent, node.step, node.waiting_for())
            waiting_since = time.monotonic()


def run_realtime_steps(bus: Bus, period: float, stop: StopFlag, parent: int) -> None:
    """One step every ``period`` seconds with whatever has arrived, until the end of the run."""
    node = bus.node
    started = time.monotonic()
    next_gap_check = started + GAP_CHECK_PERIOD
    first_step = node.step
    ranged = math.isfinite(node.scenario.comm_range)
    last_sync: dict[int, float] = {}
    while node.finished is None and not stop.stopped and not parent_is_gone(parent):
        node.handle_queued()
        if node.finished is not None:
            break
        if time.monotonic() >= next_gap_check:
            if ranged:  # a limited radio: anti-entropy with the teammates in contact (protocol.sync)
                exchange_with_contacts(bus, last_sync)
            else:
                fill_gaps(bus.session, node.keys, node.replica, node.inbox)  # teammates' deltas lost on the way
            fetch(bus.session, node.keys.go_history, node.inbox, first=END_ONLY)  # the end of the run, if lost
            next_gap_check = time.monotonic() + GAP_CHECK_PERIOD
        if bus.barrier is not None:
            node.park(bus.barrier.reached(STOPPED, "agent"))  # teammates done for good stand still
        behind = time.monotonic() - (started + (node.step - first_step) * period)
        if node.ends_on_its_own():
            break
        bus.publish(*node.control_step(late=behind >= period))
        wait = started + (node.step - first_step) * period - time.monotonic()
        if wait > 0:
            stop.wait(wait)


def exchange_with_contacts(bus: Bus, last_sync: dict[int, float]) -> None:
    """Anti-entropy (protocol.sync) with each teammate in contact, at most once every SYNC_PERIOD."""
    node = bus.node
    now = time.monotonic()
    for teammate in node.radio.in_contact():
        if now - last_sync.get(teammate, -math.inf) >= SYNC_PERIOD:
            last_sync[teammate] = now
            sync_with(bus.session, node.keys.agent_sync(teammate), node.replica, node.inbox, node.scenario.agents)


def finish_run(bus: Bus, lockstep: bool, stop: StopFlag) -> None:
    """Let in-flight deltas of teammates land, so every replica ends with the same map."""
    node = bus.node
    if lockstep and node.finished is not None:
        node.inbox.drain(0.5, node.handle)
    if lockstep and node.lost_last_go():
        # The last go (every member's last delta) was lost and the end of the run came first: it is in
        # the coordinator's history.
        bus.recover_go()
        node.handle_queued()
    if bus.barrier is not None and node.finished is not None and not stop.stopped:
        # Realtime: the last deltas of a teammate have no later one to reveal their loss; once every
        # teammate has stopped, ask every history for what follows our contiguous run, and stay until
        # every teammate's replica is whole (it may still ask ours). See protocol.settling.
        settle(bus.barrier, node.replica, node.inbox, node.handle, node.others(), lambda: stop.stopped)
    node.apply_remaining_gos()


def exit_code(node: AgentNode, stop: StopFlag) -> int:
    if node.finished is not None:
        log.info("agent %d: run %s at step %d", node.options.agent, node.finished.kind, node.finished.step)
        return EXIT_OK if node.finished.kind == "done" else EXIT_FAILED
    return stop.exit_code(EXIT_OK)
