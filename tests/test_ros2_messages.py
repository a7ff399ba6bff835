"""protocol.ros2.messages: what the driver writes is what rosbags reads, and what it reads is checked."""

from __future__ import annotations

import math

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from protocol.ros2.messages import (
    BadRosMessage,
    covariance_of,
    dds_type_name,
    decode_pose,
    encode_pose,
    encode_velocity,
    type_hash,
)
from protocol.ros2.options import ODOMETRY, POSE_WITH_COVARIANCE, TWIST, TWIST_STAMPED

STORE = get_typestore(Stores.ROS2_JAZZY)
T = STORE.types
CDR_LITTLE_ENDIAN = bytes([0x00, 0x01, 0x00, 0x00])  # XCDR1 encapsulation header, little endian


def test_a_twist_is_52_bytes_of_little_endian_cdr_that_rosbags_reads_back():
    payload = encode_velocity(0.25, -0.5, stamped=False)
    assert len(payload) == 52 and payload[:4] == CDR_LITTLE_ENDIAN
    twist = STORE.deserialize_cdr(payload, TWIST)
    assert (twist.linear.x, twist.linear.y, twist.linear.z) == (0.25, 0.0, 0.0)
    assert (twist.angular.x, twist.angular.y, twist.angular.z) == (0.0, 0.0, -0.5)


def test_a_twist_stamped_carries_the_stamp_and_frame():
    payload = encode_velocity(1.0, 0.1, stamped=True, stamp_ns=1_700_000_000_123_456_789, frame_id="bot1/base_link")
    message = STORE.deserialize_cdr(payload, TWIST_STAMPED)
    assert (message.header.stamp.sec, message.header.stamp.nanosec) == (1_700_000_000, 123_456_789)
    assert message.header.frame_id == "bot1/base_link"
    assert (message.twist.linear.x, message.twist.angular.z) == (1.0, 0.1)


def odometry(x: float, y: float, theta: float, q: tuple[float, float, float, float] | None = None) -> bytes:
    qx, qy, qz, qw = q or (0.0, 0.0, math.sin(theta / 2), math.cos(theta / 2))
    pose = T["geometry_msgs/msg/Pose"](
        position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
        orientation=T["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
    )
    zero = T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
    message = T[ODOMETRY](
        header=T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=5, nanosec=6), frame_id="odom"),
        child_frame_id="base_link",
        pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](
            twist=T[TWIST](linear=zero, angular=zero), covariance=np.zeros(36)
        ),
    )
    return bytes(STORE.serialize_cdr(message, ODOMETRY))


def test_odometry_gives_the_planar_pose_frame_and_stamp():
    read = decode_pose(odometry(1.5, -2.0, 2.0), ODOMETRY)
    assert read.pose == pytest.approx((1.5, -2.0, 2.0))
    assert read.frame_id == "odom" and read.stamp_ns == 5_000_000_006


def test_a_localiser_pose_is_read_the_same_way():
    pose = T["geometry_msgs/msg/Pose"](
        position=T["geometry_msgs/msg/Point"](x=4.0, y=5.0, z=0.0),
        orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=1.0, w=0.0),
    )
    message = T[POSE_WITH_COVARIANCE](
        header=T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="map"),
        pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
    )
    read = decode_pose(bytes(STORE.serialize_cdr(message, POSE_WITH_COVARIANCE)), POSE_WITH_COVARIANCE)
    assert read.pose[:2] == (4.0, 5.0) and abs(read.pose[2]) == pytest.approx(math.pi)
    assert read.frame_id == "map"


@pytest.mark.parametrize(
    "payload",
    [b"", b"\x00\x01\x00\x00", encode_velocity(1.0, 0.0, stamped=False), odometry(1.0, 2.0, 0.0)[:60]],
    ids=["empty", "header-only", "a-twist", "truncated"],
)
def test_bytes_that_are_not_odometry_are_rejected(payload):
    with pytest.raises(BadRosMessage):
        decode_pose(payload, ODOMETRY)


@pytest.mark.parametrize(
    "payload",
    [odometry(math.nan, 0.0, 0.0), odometry(0.0, math.inf, 0.0), odometry(0.0, 0.0, 0.0, q=(0.0, 0.0, 0.0, 0.0))],
    ids=["nan", "inf", "zero-quaternion"],
)
def test_a_pose_that_cannot_be_used_is_rejected(payload):
    with pytest.raises(BadRosMessage):
        decode_pose(payload, ODOMETRY)


def test_type_names_and_hashes_are_those_ros_2_uses():
    assert dds_type_name(TWIST) == "geometry_msgs::msg::dds_::Twist_"
    # The hash rmw_zenoh's design document shows in its Twist key (docs/design.md, jazzy).
    assert type_hash(TWIST).startswith("RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a")
    assert type_hash(TWIST, "humble") == type_hash(TWIST, "kilted") == type_hash(TWIST)


def test_a_covariance_that_says_nothing_is_none_and_one_that_does_is_read():
    assert covariance_of([0.0] * 36) is None
    given = [0.0] * 36
    given[0], given[7], given[35] = 0.01, 0.03, 0.002
    assert covariance_of(given) == pytest.approx((0.02, 0.002))
    given[35] = float("nan")
    assert covariance_of(given) is None
    given[35], given[0] = 0.002, -1.0  # a negative variance: not one
    assert covariance_of(given) is None


def test_a_fix_s_covariance_is_read_with_its_pose():
    fix = decode_pose(
        encode_pose(POSE_WITH_COVARIANCE, (1.0, 2.0, 0.5), 7, "map", sigma=(0.1, 0.05)), POSE_WITH_COVARIANCE
    )
    assert fix.pose == pytest.approx((1.0, 2.0, 0.5)) and fix.stamp_ns == 7
    assert fix.variance == pytest.approx((0.01, 0.0025))
    assert (
        decode_pose(encode_pose(POSE_WITH_COVARIANCE, (1.0, 2.0, 0.5), 7, "map"), POSE_WITH_COVARIANCE).variance is None
    )
