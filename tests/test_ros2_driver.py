"""agents.ros2.driver over real Zenoh sessions on loopback: a stand-in base made of rosbags and zenoh only
checks what the driver publishes, and feeds it poses."""

from __future__ import annotations

import math
import queue
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import pytest
import zenoh
import zenoh.ext
from rosbags.typesys import Stores, get_typestore

from agents.ros2.driver import Ros2Robot
from model.scenario import Scenario
from protocol.ros2.messages import encode_pose
from protocol.ros2.options import ODOMETRY, POSE_WITH_COVARIANCE, Ros2Options
from protocol.session import zenoh_config
from tests.teamrun import free_port, limit

STORE = get_typestore(Stores.ROS2_JAZZY)
T = STORE.types
# 1 unit per time unit = 1 m/s. A control period of 1 s (dt 20 x 0.05 s): the watchdog (3 periods without
# a command) stays out of these tests but the one about it.
SCENARIO = Scenario(metres_per_unit=0.05, seconds_per_unit=0.05, dt=20.0)


@contextmanager
def bus() -> Iterator[tuple[zenoh.Session, zenoh.Session]]:
    """A router on a free loopback port and two clients: the driver's and the base's."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    with (
        zenoh.open(zenoh_config("router", listen=[endpoint])),
        zenoh.open(zenoh_config(connect=[endpoint])) as driver,
        zenoh.open(zenoh_config(connect=[endpoint])) as base,
    ):
        yield driver, base


class Base:
    """What a base receives on its command key, decoded by rosbags; odometry it sends."""

    def __init__(self, session: zenoh.Session, command_key: str, typename: str = "geometry_msgs/msg/Twist") -> None:
        self.received: queue.Queue[tuple[object, bytes | None]] = queue.Queue()
        self.typename = typename
        session.declare_subscriber(command_key, self.on_command)
        self.session = session
        self.streaming = threading.Event()
        self.streamer: threading.Thread | None = None

    def stream_odometry(self, key: str, x: float, y: float, theta: float) -> None:
        """Odometry at 30 Hz, as a base sends it, until :meth:`stop_odometry`."""
        self.streaming.set()

        def loop() -> None:
            while self.streaming.is_set():
                self.send_odometry(key, x, y, theta)
                time.sleep(1 / 30)

        self.streamer = threading.Thread(target=loop, daemon=True)
        self.streamer.start()

    def stop_odometry(self) -> None:
        """Stop the stream: its thread has sent its last odometry when this returns."""
        self.streaming.clear()
        if self.streamer is not None:
            self.streamer.join(timeout=limit(30))
            assert not self.streamer.is_alive()
            self.streamer = None

    def on_command(self, sample: zenoh.Sample) -> None:
        message = STORE.deserialize_cdr(sample.payload.to_bytes(), self.typename)
        attachment = sample.attachment.to_bytes() if sample.attachment is not None else None
        self.received.put((message, attachment))

    def next(self) -> tuple[object, bytes | None]:
        """The next command the base receives (it waits for it: the limit only bounds a hang)."""
        return self.received.get(timeout=limit(60))

    def send_localiser_pose(self, key: str, x: float, y: float, theta: float) -> None:
        """A map-frame PoseWithCovarianceStamped stamped 0, the stamp of every odometry sent here."""
        pose = T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
            orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(theta / 2), w=math.cos(theta / 2)),
        )
        message = T["geometry_msgs/msg/PoseWithCovarianceStamped"](
            header=T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="map"),
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
        )
        self.session.put(key, bytes(STORE.serialize_cdr(message, "geometry_msgs/msg/PoseWithCovarianceStamped")))

    def send_odometry(self, key: str, x: float, y: float, theta: float) -> None:
        pose = T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
            orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(theta / 2), w=math.cos(theta / 2)),
        )
        zero = T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
        message = T["nav_msgs/msg/Odometry"](
            header=T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="odom"),
            child_frame_id="base_link",
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](
                twist=T["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)
            ),
        )
        self.session.put(key, bytes(STORE.serialize_cdr(message, "nav_msgs/msg/Odometry")))


def wait_until(condition, timeout: float = 60.0) -> bool:
    """True as soon as ``condition()`` is; False after ``timeout`` seconds (scaled): an outer limit."""
    deadline = time.monotonic() + limit(timeout)
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.01)
    return False


def robot_with_pose(
    driver: zenoh.Session, base: Base, options: Ros2Options, pose=(1.0, 2.0, 0.5), scenario: Scenario = SCENARIO
) -> Ros2Robot:
    robot = Ros2Robot(driver, options, scenario, agent=0)
    base.stream_odometry(robot.topics.odometry_key, *pose)
    assert wait_until(robot.has_pose)
    return robot


@contextmanager
def robot_on_a_base(
    options: Ros2Options = Ros2Options(namespace="bot1"),  # noqa: B008 (frozen: one default is safe)
    pose=(1.0, 2.0, 0.5),
    scenario: Scenario = SCENARIO,
    command_key: str = "bot1/cmd_vel",
    typename: str = "geometry_msgs/msg/Twist",
) -> Iterator[tuple[Ros2Robot, Base]]:
    """A driver with its pose from a base streaming odometry; closed (a zero sent) at the end."""
    with bus() as (driver, base_session):
        base = Base(base_session, command_key, typename)
        robot = robot_with_pose(driver, base, options, pose, scenario)
        try:
            yield robot, base
        finally:
            base.stop_odometry()
            robot.close()


def test_commands_are_twists_in_metres_and_radians_scaled_into_the_papers_bounds():
    with robot_on_a_base() as (robot, base):
        assert robot.current_pose() == pytest.approx((20.0, 40.0, 0.5))  # (1 m, 2 m) in units of 0.05 m
        robot.command(0.4, 0.1)
        twist, attachment = base.next()
        assert attachment is None  # the bridge route carries none
        assert twist.linear.x == pytest.approx(0.4) and twist.angular.z == pytest.approx(2.0)  # 0.1 rad / 0.05 s
        robot.command(3.0, -5.0)  # past k_v = 1 and π k_ω: both scaled by 1/3, the curvature kept
        twist, _ = base.next()
        assert twist.linear.x == pytest.approx(1.0) and twist.angular.z == pytest.approx(-5 / 3 / 0.05)
        assert robot.last_command == pytest.approx((1.0, -5 / 3))
        robot.stop()  # what close() sends first, at the end of every run
        twist, _ = base.next()
        assert (twist.linear.x, twist.angular.z) == (0.0, 0.0) and robot.last_command == (0.0, 0.0)


def test_commands_are_scaled_into_the_bases_own_limits():
    with robot_on_a_base(Ros2Options(namespace="bot1", max_linear=0.5, max_angular=10.0)) as (robot, base):
        robot.current_pose()
        robot.command(0.8, 0.4)  # 0.8 m/s and 8 rad/s on the base: 0.5 m/s caps both by 5/8
        twist, _ = base.next()
        assert twist.linear.x == pytest.approx(0.5) and twist.angular.z == pytest.approx(5.0)
        assert robot.last_command == pytest.approx((0.5, 0.25))  # what was applied, in scenario units


def test_a_command_that_is_not_a_number_is_sent_as_zero():
    with robot_on_a_base() as (robot, base):
        robot.current_pose()
        robot.command(math.nan, 0.3)
        twist, _ = base.next()
        assert (twist.linear.x, twist.angular.z) == (0.0, 0.0) and robot.counts()["non_finite_commands"] == 1


def test_rmw_zenoh_commands_go_to_the_hashed_key_with_the_attachment():
    options = Ros2Options(namespace="robot1", transport="rmw-zenoh", stamped=True, frame_id="robot1/base_link")
    with bus() as (driver, base_session):
        typename = "geometry_msgs/msg/TwistStamped"
        key = "0/robot1/cmd_vel/geometry_msgs::msg::dds_::TwistStamped_/" + STORE.hash_rihs01(typename)
        base = Base(base_session, key, typename)
        robot = robot_with_pose(driver, base, options)
        assert robot.topics.odometry_key == "0/robot1/odom/nav_msgs::msg::dds_::Odometry_/" + STORE.hash_rihs01(
            "nav_msgs/msg/Odometry"
        )
        before = time.time_ns()
        robot.current_pose()
        robot.command(0.2, 0.0)
        robot.command(0.3, 0.0)
        (first, first_attachment), (second, second_attachment) = base.next(), base.next()
        assert (first.twist.linear.x, second.twist.linear.x) == pytest.approx((0.2, 0.3))
        assert second.header.frame_id == "robot1/base_link"
        assert second.header.stamp.sec * 10**9 + second.header.stamp.nanosec >= before
        read = [
            zenoh.ext.z_deserialize(tuple[zenoh.ext.Int64, zenoh.ext.Int64, bytes], zenoh.ZBytes(a))
            for a in (first_attachment, second_attachment)
        ]
        assert [len(a) for a in (first_attachment, second_attachment)] == [33, 33]
        assert read[1][0] == read[0][0] + 1 and read[0][2] == read[1][2] and len(read[0][2]) == 16
        assert read[1][1] >= before
        base.stop_odometry()
        robot.close()


def test_stale_odometry_sends_zero_until_odometry_newer_than_the_stale_spell():
    options = Ros2Options(namespace="bot1", pose_timeout=0.2)
    with robot_on_a_base(options) as (robot, base):
        assert robot.current_pose() is not None
        base.stop_odometry()
        # Stale once the last odometry (however late a busy machine delivers it) is pose_timeout old.
        assert wait_until(lambda: robot.current_pose() is None)
        robot.command(1.0, 0.5)
        twist, _ = base.next()
        assert (twist.linear.x, twist.angular.z) == (0.0, 0.0) and robot.last_command == (0.0, 0.0)
        base.stream_odometry("bot1/odom", 1.0, 2.0, 0.5)
        assert wait_until(lambda: robot.current_pose() is not None)
        robot.command(1.0, 0.0)
        twist, _ = base.next()
        assert twist.linear.x == pytest.approx(1.0)
        assert robot.counts()["stale_spells"] == 1


def test_a_step_acts_on_the_pose_it_read_even_if_a_newer_one_arrives_before_its_command():
    with robot_on_a_base() as (robot, base):
        acting = robot.current_pose()
        base.stop_odometry()
        base.stream_odometry("bot1/odom", 3.0, 3.0, 0.0)  # the base moved meanwhile
        assert wait_until(lambda: robot.pose()[0] == pytest.approx(60.0))
        assert robot.command(0.0, 0.0) == pytest.approx(acting)  # the step's end, from the pose it acted on


def test_odometry_is_placed_by_the_map_from_odom_offset_and_the_origin():
    offset = (2.0, 1.0, math.pi / 2)
    options = Ros2Options(namespace="bot1", odom_offset=offset, origin=(-1.0, 0.0))
    with robot_on_a_base(options, pose=(1.0, 0.0, 0.0)) as (robot, _):
        # odom (1, 0, 0) is map (2, 2, π/2); the scenario's (0, 0) is map (−1, 0); units of 0.05 m.
        assert robot.pose() == pytest.approx((60.0, 40.0, math.pi / 2))


def test_a_localiser_pose_corrects_map_from_odom_and_odometry_carries_it_on():
    with bus() as (driver, base_session):
        base = Base(base_session, "bot1/cmd_vel")
        robot = Ros2Robot(driver, Ros2Options(namespace="bot1", localiser_topic="amcl_pose"), SCENARIO, agent=0)
        base.stream_odometry("bot1/odom", 1.0, 0.0, 0.0)
        assert wait_until(lambda: robot.counts()["poses_received"] > 0)
        assert not robot.has_pose()  # no map pose until the localiser speaks
        assert wait_until(
            lambda: (base.send_localiser_pose("bot1/amcl_pose", 2.0, 2.0, math.pi / 2), robot.has_pose())[1]
        )
        assert robot.pose() == pytest.approx((40.0, 40.0, math.pi / 2))
        base.stop_odometry()
        base.stream_odometry("bot1/odom", 2.0, 0.0, 0.0)  # 1 m ahead in odom: 1 m along map y
        assert wait_until(lambda: robot.pose()[1] == pytest.approx(60.0))
        assert robot.pose() == pytest.approx((40.0, 60.0, math.pi / 2))
        base.stop_odometry()
        robot.close()


def test_against_the_simulator_in_lockstep_each_step_waits_for_the_next_simulated_instant():
    """--ros-sim-time in lockstep (anicov sim): a step acts on the instant after the last one acted on, however
    often the current one is repeated; a fix stamped ahead of the odometry waits for it; nothing is sent but
    the steps' commands (no watchdog zero, no stop: a zero would count as the next step's command)."""
    options = Ros2Options(namespace="bot1", localiser_topic="amcl_pose", sim_time=True, lockstep=True)
    with bus() as (driver, base_session):
        base = Base(base_session, "bot1/cmd_vel")
        robot = Ros2Robot(driver, options, SCENARIO, agent=0)

        def put(topic: str, typename: str, pose: tuple[float, float, float], stamp: int) -> None:
            base_session.put(f"bot1/{topic}", encode_pose(typename, pose, stamp, "map"))

        def first_instant() -> bool:  # repeated, as the simulator repeats it, until the driver's subscriber is up
            put("amcl_pose", POSE_WITH_COVARIANCE, (1.0, 2.0, 0.0), 0)  # before any odometry of its instant
            put("odom", ODOMETRY, (0.0, 0.0, 0.0), 0)
            return robot.has_pose()

        assert wait_until(first_instant)
        assert robot.current_pose() == pytest.approx((20.0, 40.0, 0.0))  # 0.05 m units
        robot.command(0.5, 0.0)
        assert base.next()[0].linear.x == pytest.approx(0.5 * 0.05 / 0.05)
        acted: list = []
        step = threading.Thread(target=lambda: acted.append(robot.current_pose()), daemon=True)
        step.start()
        put("odom", ODOMETRY, (0.0, 0.0, 0.0), 0)  # the simulator repeating instant 0 while it waits
        step.join(timeout=1.0)
        assert step.is_alive()  # still waiting: the repeat is not the next instant
        put("odom", ODOMETRY, (0.1, 0.0, 0.0), 100_000_000)
        step.join(timeout=limit(30))
        assert acted == [pytest.approx((22.0, 40.0, 0.0))]
        robot.close()  # sends no stop
        time.sleep(3.5)  # the watchdog's 3 periods of 1 s, had it run
        assert base.received.empty() and robot.counts()["commands_sent"] == 1


def test_a_fix_sent_before_the_odometry_of_its_instant_is_read_before_it():
    """The simulator sends an instant's fixes, then its odometry: a step against it acts on the corrected pose
    every time (one subscriber keeps the order; two did not, under load, and a lockstep run then differed)."""
    options = Ros2Options(namespace="bot1", localiser_topic="amcl_pose", sim_time=True, lockstep=True)
    with bus() as (driver, base_session):
        base = Base(base_session, "bot1/cmd_vel")
        robot = Ros2Robot(driver, options, SCENARIO, agent=0)
        acted = []
        for instant in range(100):
            fix = (1.0 + 0.01 * instant, 2.0, 0.0)  # the localiser's: the odometry below is off by it

            def send(fix: tuple[float, float, float] = fix, instant: int = instant) -> bool:
                base_session.put("bot1/amcl_pose", encode_pose(POSE_WITH_COVARIANCE, fix, instant * 10**8, "map"))
                base_session.put("bot1/odom", encode_pose(ODOMETRY, (0.0, 0.0, 0.0), instant * 10**8, "odom"))
                return robot.has_pose()

            if instant == 0:  # repeated until the driver's subscriber is up, as the simulator repeats it
                assert wait_until(send)
            else:
                send()
            acted.append(robot.current_pose())
            robot.command(0.0, 0.0)
            base.next()
        assert acted == [pytest.approx((20.0 + 0.2 * instant, 40.0, 0.0)) for instant in range(100)]
        robot.close()


def test_with_the_scenario_s_noise_a_later_fix_moves_the_pose_by_the_kalman_gain_as_the_belief_does():
    """The first fix places the robot whole; the odometry's drift over 1 m (20 units) grows its doubt; the next
    fix, 0.1 m off, moves it by P / (P + σ²) of that (model.physics.noise), not whole: a pose that jumped by
    σ at every fix swung a standing robot's heading (docs/physics.md)."""
    from model.physics.noise import noise_of, predicted_variance
    from model.scenario import validate

    noise = {"localiser_sigma": 2.0, "odometry_per_metre": 0.3, "localiser_rate": 0.05, "clearance_reserve": 0.0}
    given = {**SCENARIO.to_dict(), "robot_radius": 1.0, "physics": "mujoco", "safety_range": 200.0, "noise": noise}
    scenario = validate(given)
    variance = predicted_variance(np.zeros((1, 2)), np.array([[20.0, 0.0, 0.0]]), noise_of(scenario))
    gain = variance[0, 0] / (variance[0, 0] + 2.0**2)
    options = Ros2Options(namespace="bot1", localiser_topic="amcl_pose", sim_time=True, lockstep=True)
    with bus() as (driver, base_session):
        base = Base(base_session, "bot1/cmd_vel")
        robot = Ros2Robot(driver, options, scenario, agent=0)

        def instant(stamp: int, odometry: tuple[float, float, float], fix: tuple[float, float, float]) -> bool:
            base_session.put("bot1/amcl_pose", encode_pose(POSE_WITH_COVARIANCE, fix, stamp, "map"))
            base_session.put("bot1/odom", encode_pose(ODOMETRY, odometry, stamp, "odom"))
            return robot.has_pose()

        assert wait_until(lambda: instant(0, (0.0, 0.0, 0.0), (1.0, 2.0, 0.0)))
        assert robot.current_pose() == pytest.approx((20.0, 40.0, 0.0))  # the first fix, whole
        robot.command(0.0, 0.0)
        base.next()
        instant(10**8, (1.0, 0.0, 0.0), (2.1, 2.0, 0.0))  # 1 m on by odometry; the fix 0.1 m further
        assert robot.current_pose() == pytest.approx((20.0 + 20.0 + 2.0 * gain, 40.0, 0.0))
        assert 0.05 < gain < 0.95
        heard = robot.counts()["poses_received"]
        instant(10**8, (1.0, 0.0, 0.0), (2.1, 2.0, 0.0))  # sent again, as the simulator does while it waits
        assert wait_until(lambda: robot.counts()["poses_received"] > heard)  # the odometry after the fix: both read
        assert robot.pose() == pytest.approx((20.0 + 20.0 + 2.0 * gain, 40.0, 0.0))  # taken once
        assert robot.counts()["localiser_poses"] == 2
        robot.close()


def test_a_fix_s_own_covariance_is_its_doubt_when_first_and_its_weight_after():
    """A real localiser says how sure each fix is (the covariance's diagonal): the first fix, taken whole, leaves
    the robot that doubt; a later one moves it by P / (P + its own variance); one that says nothing (all zero,
    ROS's "unknown") is weighed by the scenario's σ."""
    from model.scenario import validate

    noise = {"localiser_sigma": 2.0, "odometry_per_metre": 0.3, "localiser_rate": 0.05, "clearance_reserve": 0.0}
    given = {**SCENARIO.to_dict(), "robot_radius": 1.0, "physics": "mujoco", "safety_range": 200.0, "noise": noise}
    scenario = validate(given)
    options = Ros2Options(namespace="bot1", localiser_topic="amcl_pose", sim_time=True, lockstep=True)
    with bus() as (driver, base_session):
        base = Base(base_session, "bot1/cmd_vel")
        robot = Ros2Robot(driver, options, scenario, agent=0)

        def instant(stamp: int, fix: tuple[float, float, float], sigma: tuple[float, float]) -> bool:
            base_session.put("bot1/amcl_pose", encode_pose(POSE_WITH_COVARIANCE, fix, stamp, "map", sigma=sigma))
            base_session.put("bot1/odom", encode_pose(ODOMETRY, (0.0, 0.0, 0.0), stamp, "odom"))
            return robot.has_pose()

        def step() -> None:
            robot.command(0.0, 0.0)
            base.next()

        # The odometry stands still: P grows by no drift between the fixes.
        assert wait_until(lambda: instant(0, (1.0, 2.0, 0.0), (0.1, 0.05)))  # 0.1 m: 2 units, P = 4
        assert robot.current_pose() == pytest.approx((20.0, 40.0, 0.0))
        step()
        instant(10**8, (1.1, 2.0, 0.0), (0.1, 0.05))  # 2 units off, its own variance 4: gain 1/2
        assert robot.current_pose() == pytest.approx((21.0, 40.0, 0.0))
        step()
        instant(2 * 10**8, (1.15, 2.0, 0.0), (0.0, 0.0))  # 2 units off again; the scenario's σ² = 4, P = 2
        assert robot.current_pose() == pytest.approx((21.0 + 2.0 / 3.0, 40.0, 0.0))
        robot.close()


def test_without_a_model_of_the_odometry_s_drift_every_fix_is_taken_whole_whatever_its_covariance():
    """A scenario with no [noise] (a real robot's, scenarios/ros2-paper.toml) has no drift to weigh a fix against:
    the doubt would never grow, a fix's gain would fall as 1 / n and the localiser would be ignored."""
    options = Ros2Options(namespace="bot1", localiser_topic="amcl_pose", sim_time=True, lockstep=True)
    with bus() as (driver, base_session):
        base = Base(base_session, "bot1/cmd_vel")
        robot = Ros2Robot(driver, options, SCENARIO, agent=0)

        def instant(stamp: int, fix: tuple[float, float, float]) -> bool:
            base_session.put("bot1/amcl_pose", encode_pose(POSE_WITH_COVARIANCE, fix, stamp, "map", sigma=(0.1, 0.05)))
            base_session.put("bot1/odom", encode_pose(ODOMETRY, (0.0, 0.0, 0.0), stamp, "odom"))
            return robot.has_pose()

        assert wait_until(lambda: instant(0, (1.0, 2.0, 0.0)))
        assert robot.current_pose() == pytest.approx((20.0, 40.0, 0.0))
        for step, x in enumerate((1.1, 1.3, 1.2), start=1):
            robot.command(0.0, 0.0)
            base.next()
            instant(step * 10**8, (x, 2.0, 0.0))
            assert robot.current_pose() == pytest.approx((20.0 * x, 40.0, 0.0))  # whole
        robot.close()


def test_a_payload_that_is_not_a_pose_is_rejected_and_counted():
    with bus() as (driver, base_session):
        robot = Ros2Robot(driver, Ros2Options(namespace="bot1"), SCENARIO, agent=0)
        assert wait_until(
            lambda: (base_session.put("bot1/odom", b"\x00\x01\x00\x00 not odometry"), robot.counts()["poses_rejected"])[
                1
            ]
        )
        assert not robot.has_pose()
        with pytest.raises(RuntimeError, match="no pose yet on bot1/odom"):
            robot.pose()
        robot.close()


def test_waiting_for_a_pose_says_where_and_gives_up_when_stopped(caplog):
    with bus() as (driver, _):
        robot = Ros2Robot(driver, Ros2Options(namespace="bot7"), SCENARIO, agent=3)
        calls = iter(range(3))
        with caplog.at_level("INFO", logger="anicov.ros2"):
            assert not robot.wait_for_pose(lambda: next(calls, 3) >= 2, lambda: False)
        assert "agent 3 waits for its robot's pose: nav_msgs/msg/Odometry on Zenoh key bot7/odom" in caplog.text
        robot.close()


def test_the_watchdog_stops_the_base_when_the_control_loop_falls_silent():
    fast = Scenario(metres_per_unit=0.05, seconds_per_unit=0.05, dt=0.5)  # a command every 25 ms
    with robot_on_a_base(Ros2Options(namespace="bot1"), scenario=fast) as (robot, base):
        robot.current_pose()
        robot.command(0.5, 0.0)
        moving, _ = base.next()
        assert moving.linear.x == pytest.approx(0.5)
        stopped, _ = base.next()  # nothing more from the loop: 3 periods on, the watchdog's zero
        assert (stopped.linear.x, stopped.angular.z) == (0.0, 0.0)
        assert robot.counts()["watchdog_stops"] == 1
        time.sleep(0.2)
        assert base.received.empty()  # one zero, not a stream of them


def test_robot_of_sends_zero_however_its_block_ends():
    """agents.process.robot_of, which the agent's whole run is inside: here an exception, as a bug in the
    control loop would raise, is the end."""
    from agents.process import AgentOptions, robot_of

    with bus() as (driver, base_session):
        base = Base(base_session, "bot1/cmd_vel")
        with pytest.raises(RuntimeError, match="a bug"):
            with robot_of(driver, SCENARIO, AgentOptions("t", 0), Ros2Options(namespace="bot1")) as robot:
                base.stream_odometry("bot1/odom", 1.0, 2.0, 0.5)
                assert wait_until(robot.has_pose)
                robot.current_pose()
                robot.command(0.7, 0.0)
                raise RuntimeError("a bug in the control loop")
        base.stop_odometry()
        moving, _ = base.next()
        stopped, _ = base.next()
        assert moving.linear.x == pytest.approx(0.7)
        assert (stopped.linear.x, stopped.angular.z) == (0.0, 0.0) and base.received.empty()
