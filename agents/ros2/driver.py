"""The ROS 2 base behind an agent: :class:`Ros2Robot` implements :class:`agents.robot.Robot` over Zenoh.

It publishes velocity commands on the base's command topic and keeps the latest odometry (callback
thread, under a lock); with a localiser (``localiser_topic``, e.g. AMCL's ``amcl_pose``) each of its
poses corrects the map ← odom transform, as ROS's own map → odom tf does, otherwise that transform is
the fixed ``odom_offset``. Where the scenario's ``[noise]`` states the localiser's σ, a fix moves the pose by
the Kalman gain of the odometry's doubt against the fix's, as the in-process belief does
(:mod:`model.physics.noise`: the odometry's drift grows the doubt as the robot travels); without it a fix is
taken whole. Odometry is what tells whether the pose is fresh: a localiser publishes only
when its filter updates (AMCL: after 0.2 m or 0.5 rad of motion by default), so a robot standing still
would never hear from it. What the driver does for a real base's sake:

- the pose a step acts on is read once, with its freshness, under the lock (:meth:`current_pose`), and
  the same pose gives the step's predicted end (:meth:`command`): a pose arriving in between cannot
  pair an old position with a new verdict;
- every command is scaled, v and ω by one factor so the path keeps its curvature, into the paper's
  bounds (|v| ≤ k_v, |ω| ≤ π k_ω: eq. 15–16) and the base's (``max_linear`` m/s, ``max_angular``
  rad/s); a command that is not a finite number is sent as zero;
- odometry older than ``pose_timeout`` seconds is stale: :meth:`current_pose` is None, the robot is
  sent zero and the agent holds its step and says so, until odometry that arrived after that moment;
- a watchdog thread sends zero when the control loop has sent nothing for ``WATCHDOG_PERIODS`` control
  periods (a blocking recovery query, a pause): the base does not roll on the last command meanwhile;
- against ``anicov sim`` in lockstep (``sim_time``, ROS's use_sim_time) a step acts on the odometry of the
  simulated instant after the one it acted on last (the simulator steps once every robot's command is in), not on
  the freshest by the wall clock; no watchdog and no stop: the simulated base moves only when the world steps;
- a localiser's fix stamped later than the newest odometry waits for the odometry of its instant;
- :meth:`stop` sends zero (reliably, at once); the agent process calls it when its loop ends for any
  reason (end of run, Ctrl-C, SIGTERM, SIGHUP, an exception) before the sessions close. A lost router
  cannot carry that zero: the base's own command timeout must stop it then (deploy/ros2.md's checklist),
  and the stale odometry keeps the agent from moving it again before fresh odometry comes through.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections import deque
from collections.abc import Callable

import numpy as np
import zenoh

from model.paper.dynamics import unicycle_step
from model.physics.noise import fix_gains, fused, gains_against, noise_of, predicted_variance
from model.scenario import Scenario
from protocol.ros2.frames import Pose, compose, frame_of, invert, scale_into
from protocol.ros2.messages import BadRosMessage, RosPose, decode_pose, encode_velocity
from protocol.ros2.options import ODOMETRY, POSE_WITH_COVARIANCE, Ros2Options
from protocol.ros2.transport import Ros2Topics

log = logging.getLogger("anicov.ros2")

WAIT_LOG_PERIOD = 2.0
"""Seconds between the 'waiting for a pose' lines while the agent waits for its robot."""
WATCHDOG_PERIODS = 3
"""Control periods without a command after which the watchdog sends zero."""
SIM_WAIT_LIMIT = 60.0
"""Lockstep against anicov sim: wall seconds a step waits for the next simulated instant before it holds (the
simulator steps as soon as every robot's command is in: only a simulator that died makes it wait this long)."""
ODOMETRY_HISTORY = 256
"""Odometry poses kept to pair a localiser's pose with the odometry of the same instant (8 s at 30 Hz)."""


class Ros2Robot:
    """A ROS 2 base commanded over Zenoh; poses and commands in scenario units (see :mod:`.frames`)."""

    def __init__(self, session: zenoh.Session, options: Ros2Options, scenario: Scenario, agent: int) -> None:
        self.options, self.agent = options, agent
        self.frame = frame_of(scenario, options.origin)
        self._bounds = (scenario.k_v, math.pi * scenario.k_omega)  # eq. 15–16, scenario units
        self._dt = scenario.dt
        self._period = scenario.dt * scenario.seconds_per_unit  # wall seconds of one control step
        self.topics = Ros2Topics.of(options)
        self._session = session
        self._stepped_by_simulator = options.sim_time and options.lockstep
        # Against the simulator in lockstep a lost command would hold the world's step: none may be dropped.
        congestion = zenoh.CongestionControl.BLOCK if self._stepped_by_simulator else zenoh.CongestionControl.DROP
        self._publisher = session.declare_publisher(
            self.topics.command_key, priority=zenoh.Priority.REAL_TIME, express=True, congestion_control=congestion
        )
        self._lock = threading.Condition()  # the callbacks' state below; notified on every odometry
        self._odometry: Pose | None = None  # odom frame, metres
        self._received_at = -math.inf  # monotonic seconds of the latest odometry
        self._history: deque[tuple[int, Pose]] = deque(maxlen=ODOMETRY_HISTORY)  # (stamp ns, odom pose)
        self._early_fix: RosPose | None = None  # a localiser's fix stamped after the newest odometry
        self._acted_stamp: int | None = None  # sim_time: the stamp of the odometry the last step acted on
        self._offset: Pose | None = None if options.localiser_topic else options.odom_offset  # map ← odom
        self._noise, self._metres_per_unit = noise_of(scenario), scenario.metres_per_unit
        self._variance = np.zeros((1, 2))  # the pose's doubt (scenario units², rad²): the first fix is the start
        # A fix's covariance is weighed only against a model of the odometry's drift: without one the doubt never
        # grows, a fix's gain would fall as 1 / n, and the localiser would be ignored; each fix is then taken whole.
        self._weighs = self._noise.odometry_per_metre > 0.0 or self._noise.odometry_per_radian > 0.0
        self._fused_stamp: int | None = None  # the stamp of the latest fix taken: a fix sent again is not taken again
        self._stale_since: float | None = None  # control thread only: the odometry went stale then
        self._acting: Pose | None = None  # control thread only: the pose this step acts on (None: hold)
        self._send_lock = threading.Lock()  # the control loop and the watchdog both send
        self._last_sent_at = math.inf  # monotonic seconds of the latest command (inf: none yet)
        self._moving = False  # the latest command sent was not zero
        self.counters = {"poses_received": 0, "poses_rejected": 0, "localiser_poses": 0, "commands_sent": 0}
        self.counters |= {"stale_spells": 0, "watchdog_stops": 0, "non_finite_commands": 0}
        self.last_command: tuple[float, float] = (0.0, 0.0)  # applied, scenario units
        self._subscribers = self._subscribe(session)
        self._closing = threading.Event()
        self._watchdog = threading.Thread(target=self._watch, name=f"ros2-watchdog-{agent}", daemon=True)
        if not self._stepped_by_simulator:
            self._watchdog.start()

    # ------------------------------------------------------------ messages in (Zenoh's threads)

    def _subscribe(self, session: zenoh.Session) -> list[zenoh.Subscriber]:
        """The odometry's subscriber and the localiser's; one for both when their keys share a parent (bridge
        keys): Zenoh keeps the order of one subscriber's samples but not across two (measured here: of 3,000
        pairs put in order on two keys, 1,844 arrived the other way round on two subscribers, none on one), and
        a fix sent before the odometry of its instant must be read before it."""
        handlers = {self.topics.odometry_key: self._on_odometry}
        if self.topics.localiser_key:
            handlers[self.topics.localiser_key] = self._on_localiser
        parents = {key.rpartition("/")[0] for key in handlers}
        if len(handlers) == 1 or len(parents) != 1:
            return [session.declare_subscriber(key, handler) for key, handler in handlers.items()]
        parent = parents.pop()

        def dispatch(sample: zenoh.Sample) -> None:
            handler = handlers.get(str(sample.key_expr))
            if handler is not None:  # the parent's other topics (our own commands among them) are not ours to read
                handler(sample)

        return [session.declare_subscriber(f"{parent}/*" if parent else "*", dispatch)]

    def _decode(self, sample: zenoh.Sample, typename: str) -> RosPose | None:
        try:
            return decode_pose(sample.payload.to_bytes(), typename, self.options.distribution)
        except BadRosMessage as error:
            with self._lock:
                self.counters["poses_rejected"] += 1
                rejected = self.counters["poses_rejected"]
            if rejected == 1 or rejected % 100 == 0:
                log.warning(
                    "agent %d: rejected a pose on %s (%d so far): %s", self.agent, sample.key_expr, rejected, error
                )
            return None

    def _on_odometry(self, sample: zenoh.Sample) -> None:
        read = self._decode(sample, ODOMETRY)
        if read is None:
            return
        with self._lock:
            if self._odometry is not None:
                self._variance = predicted_variance(
                    self._variance, self._motion(self._odometry, read.pose), self._noise
                )
            self._odometry = read.pose
            self._received_at = time.monotonic()
            self._history.append((read.stamp_ns, read.pose))
            self.counters["poses_received"] += 1
            if self._early_fix is not None and self._early_fix.stamp_ns <= read.stamp_ns:
                self._correct(self._early_fix)
                self._early_fix = None
            self._lock.notify_all()

    def _on_localiser(self, sample: zenoh.Sample) -> None:
        """A map-frame pose: map ← odom = pose ⊕ (odometry of the same instant)⁻¹."""
        read = self._decode(sample, POSE_WITH_COVARIANCE)
        if read is None:
            return
        with self._lock:
            if not self._history or read.stamp_ns > self._history[-1][0]:
                self._early_fix = read  # its instant's odometry is still on its way
                return
            self._correct(read)

    def _correct(self, fix: RosPose) -> None:
        """map ← odom from a fix and the odometry nearest its stamp (under the lock): the first taken whole, with
        the doubt its covariance gives (none where it gives none: the operator's initial pose, as the simulator
        sends the start); later ones by their gain against their covariance, or the scenario's σ where they give
        none or the scenario models no odometry drift (:attr:`_weighs`); each once (the simulator in lockstep sends
        an instant's readings again while it waits for commands; fused twice, a fix would count as two)."""
        if self._fused_stamp is not None and fix.stamp_ns <= self._fused_stamp:
            return
        self._fused_stamp = fix.stamp_ns
        _, odometry = min(self._history, key=lambda entry: abs(entry[0] - fix.stamp_ns))
        pose = fix.pose
        measured = None
        if fix.variance is not None and self._weighs:  # metres² to the scenario's units²
            measured = np.array([[fix.variance[0] / self._metres_per_unit**2, fix.variance[1]]])
        if self._offset is None:
            if measured is not None:
                self._variance = measured
        else:
            gains = (
                fix_gains(self._variance, self._noise) if measured is None else gains_against(self._variance, measured)
            )
            pose = tuple(fused(np.array([compose(self._offset, odometry)]), np.array([fix.pose]), gains)[0])
            self._variance = (1.0 - gains) * self._variance
        self._offset = compose(pose, invert(odometry))
        self.counters["localiser_poses"] += 1

    def _motion(self, before: Pose, after: Pose) -> np.ndarray:
        """(1, 3) the base's motion between two odometry poses, in its own frame and the scenario's units."""
        x, y, turn = compose(invert(before), after)
        return np.array([[x / self._metres_per_unit, y / self._metres_per_unit, turn]])

    # ------------------------------------------------------------ pose (the control thread)

    def _snapshot(self) -> tuple[Pose | None, float]:
        """The latest map-frame pose (None until odometry and the map ← odom transform are both known)
        and when its odometry arrived, read together."""
        with self._lock:
            return self._snapshot_locked()

    def _snapshot_locked(self) -> tuple[Pose | None, float]:
        if self._odometry is None or self._offset is None:
            return None, -math.inf
        return compose(self._offset, self._odometry), self._received_at

    def pose(self) -> Pose:
        """The latest pose, fresh or not (hellos, held steps)."""
        map_pose, _ = self._snapshot()
        if map_pose is None:
            raise RuntimeError(f"agent {self.agent}: no pose yet on {self.topics.odometry_key}")
        return self.frame.to_scenario(map_pose)

    def has_pose(self) -> bool:
        return self._snapshot()[0] is not None

    def current_pose(self) -> Pose | None:
        """The pose this step acts on, or None while the odometry is stale: older than ``pose_timeout``,
        or, after a stale spell, not newer than its start. Says when the robot stops and moves again. Against
        anicov sim in lockstep: the next simulated instant's (:meth:`_next_simulated_pose`)."""
        if self._stepped_by_simulator:
            return self._next_simulated_pose()
        map_pose, received = self._snapshot()
        now = time.monotonic()
        fresh = map_pose is not None and now - received <= self.options.pose_timeout
        if fresh and self._stale_since is not None:
            fresh = received > self._stale_since
            if fresh:
                log.warning(
                    "agent %d: a fresh pose on %s after %.2f s: the robot moves again",
                    self.agent, self.topics.odometry_key, now - self._stale_since,
                )  # fmt: skip
                self._stale_since = None
        elif not fresh and self._stale_since is None:
            self._stale_since = now
            self.counters["stale_spells"] += 1
            log.warning(
                "agent %d: no pose on %s for %.2f s: the robot is stopped until a fresh one arrives",
                self.agent, self.topics.odometry_key, now - received,
            )  # fmt: skip
        self._acting = self.frame.to_scenario(map_pose) if fresh and map_pose is not None else None
        return self._acting

    def _next_simulated_pose(self) -> Pose | None:
        """Lockstep against anicov sim: the pose of the simulated instant after the one the last step acted on
        (None, a held step, if the simulator did not step within SIM_WAIT_LIMIT seconds)."""
        deadline = time.monotonic() + SIM_WAIT_LIMIT
        with self._lock:
            while not self._closing.is_set():
                stamp = self._history[-1][0] if self._history else None
                ready = stamp is not None and self._offset is not None
                if ready and (self._acted_stamp is None or stamp > self._acted_stamp):
                    self._acted_stamp = stamp
                    map_pose, _ = self._snapshot_locked()
                    self._acting = self.frame.to_scenario(map_pose) if map_pose is not None else None
                    return self._acting
                if not self._lock.wait(timeout=max(0.0, min(0.5, deadline - time.monotonic()))):
                    if time.monotonic() >= deadline:
                        break
        self.counters["stale_spells"] += 1
        log.warning(
            "agent %d: the simulator gave no next instant in %.0f s: this step holds", self.agent, SIM_WAIT_LIMIT
        )
        self._acting = None
        return None

    def wait_for_pose(self, stopped: Callable[[], bool], give_up: Callable[[], bool]) -> bool:
        """Block until a first pose can be formed, saying where it waits; False if ``stopped()`` or
        ``give_up()`` first."""
        next_line = time.monotonic()
        while not self.has_pose():
            if stopped() or give_up():
                return False
            if time.monotonic() >= next_line:
                log.info("agent %d waits for its robot's pose: %s", self.agent, self.topics.describe_pose())
                next_line = time.monotonic() + WAIT_LOG_PERIOD
            time.sleep(0.02)
        log.info("agent %d: robot pose %s from %s", self.agent, _rounded(self.pose()), self.topics.odometry_key)
        return True

    # ------------------------------------------------------------ commands

    def command(self, v: float, omega: float) -> Pose:
        """Send (v, ω) (scenario units, scaled into the bounds; zero unless this step's
        :meth:`current_pose` was fresh); return where the base gets in one period if it follows (eq. 1)
        from that same pose, for teammates until its next odometry."""
        acting = self._acting
        if not (math.isfinite(v) and math.isfinite(omega)):
            self.counters["non_finite_commands"] += 1
            log.error("agent %d: the law gave a command that is not a number (%r, %r): sent zero", self.agent, v, omega)
            v = omega = 0.0
        if acting is None:
            v = omega = 0.0
        v, omega = scale_into(v, omega, *self._bounds)
        linear, angular = scale_into(
            *self.frame.to_ros_velocity(v, omega), self.options.max_linear, self.options.max_angular
        )
        self._send(linear, angular)
        self.last_command = self.frame.to_scenario_velocity(linear, angular)
        return unicycle_step(*(acting or self.pose()), *self.last_command, self._dt)

    def stop(self) -> None:
        """Zero velocity, now, and not dropped on a congested link (a base the simulator steps in lockstep moves
        only on a step's command: nothing to stop, and a zero would count as the next step's)."""
        if self._stepped_by_simulator:
            self.last_command = (0.0, 0.0)
            return
        self._send(0.0, 0.0, reliably=True)
        self.last_command = (0.0, 0.0)

    def _send(self, linear: float, angular: float, reliably: bool = False) -> None:
        with self._send_lock:
            self._send_locked(linear, angular, reliably)

    def _send_locked(self, linear: float, angular: float, reliably: bool) -> None:
        payload = encode_velocity(
            linear, angular, self.options.stamped, time.time_ns(), self.options.frame_id, self.options.distribution
        )
        self.counters["commands_sent"] += 1
        attachment = self.topics.attachment(self.counters["commands_sent"])
        if reliably:
            self._session.put(
                self.topics.command_key,
                payload,
                attachment=attachment,
                congestion_control=zenoh.CongestionControl.BLOCK,
                priority=zenoh.Priority.REAL_TIME,
                express=True,
            )
        else:
            self._publisher.put(payload, attachment=attachment)
        self._last_sent_at = time.monotonic()
        self._moving = (linear, angular) != (0.0, 0.0)

    def _watch(self) -> None:
        """Zero to the base when the control loop has been silent for WATCHDOG_PERIODS periods while the
        base moves; checked and sent under the send lock, so it never lands after a newer command."""
        silence = WATCHDOG_PERIODS * self._period
        while not self._closing.wait(self._period):
            with self._send_lock:
                quiet = time.monotonic() - self._last_sent_at
                if quiet > silence and self._moving:
                    self.counters["watchdog_stops"] += 1
                    log.warning("agent %d: no command for %.2f s: the watchdog stops the robot", self.agent, quiet)
                    self._send_locked(0.0, 0.0, reliably=True)

    def close(self) -> None:
        """Stop the base and leave the bus."""
        self._closing.set()
        try:
            self.stop()
        finally:
            if self._watchdog.is_alive():
                self._watchdog.join(timeout=1.0)
            for subscriber in self._subscribers:
                subscriber.undeclare()
            self._publisher.undeclare()

    def counts(self) -> dict[str, int]:
        return dict(self.counters)


def _rounded(pose: Pose) -> tuple[float, float, float]:
    return round(pose[0], 3), round(pose[1], 3), round(pose[2], 3)
