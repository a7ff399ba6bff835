"""ROS 2 messages as CDR bytes, by rosbags' typestore (no hand-written CDR).

The driver sends ``geometry_msgs/msg/Twist`` or ``TwistStamped`` and reads ``nav_msgs/msg/Odometry`` or
``geometry_msgs/msg/PoseWithCovarianceStamped``; the simulator (simulator/) reads the first two and writes the
others. The definitions are those of the ROS 2 distribution
named (``jazzy`` by default; these four types are the same in humble, jazzy and kilted), and so are the
RIHS01 type hashes rmw_zenoh puts in its keys.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from protocol.ros2.frames import Pose, yaw_of_quaternion
from protocol.ros2.options import ODOMETRY, POSE_WITH_COVARIANCE, TWIST, TWIST_STAMPED

DISTRIBUTIONS = ("humble", "jazzy", "kilted")


class BadRosMessage(ValueError):
    """A payload that is not the expected ROS message, or holds a pose that cannot be used."""


@cache
def typestore(distribution: str = "jazzy") -> Any:
    from rosbags.typesys import Stores, get_typestore

    if distribution not in DISTRIBUTIONS:
        raise ValueError(f"--ros-distro: expected one of {', '.join(DISTRIBUTIONS)}, got {distribution!r}")
    return get_typestore(getattr(Stores, f"ROS2_{distribution.upper()}"))


def type_hash(typename: str, distribution: str = "jazzy") -> str:
    """The RIHS01 hash of a message type (REP 2016), as ``RIHS01_<64 hex digits>``."""
    return str(typestore(distribution).hash_rihs01(typename))


def dds_type_name(typename: str) -> str:
    """``geometry_msgs/msg/Twist`` → ``geometry_msgs::msg::dds_::Twist_`` (the DDS name ROS 2 uses)."""
    package, kind, name = typename.split("/")
    return f"{package}::{kind}::dds_::{name}_"


def encode_velocity(
    linear: float, angular: float, stamped: bool, stamp_ns: int = 0, frame_id: str = "", distribution: str = "jazzy"
) -> bytes:
    """A velocity command as CDR: Twist (linear.x, angular.z), or TwistStamped with a header."""
    store = typestore(distribution)
    types = store.types
    twist = types[TWIST](
        linear=types["geometry_msgs/msg/Vector3"](x=float(linear), y=0.0, z=0.0),
        angular=types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=float(angular)),
    )
    if not stamped:
        return bytes(store.serialize_cdr(twist, TWIST))
    seconds, nanoseconds = divmod(int(stamp_ns), 1_000_000_000)
    header = types["std_msgs/msg/Header"](
        stamp=types["builtin_interfaces/msg/Time"](sec=seconds, nanosec=nanoseconds), frame_id=frame_id
    )
    return bytes(store.serialize_cdr(types[TWIST_STAMPED](header=header, twist=twist), TWIST_STAMPED))


@dataclass(frozen=True)
class RosPose:
    """A planar pose read from a message: metres and radians in the message's frame."""

    pose: Pose
    frame_id: str
    stamp_ns: int
    variance: tuple[float, float] | None = None  # (m² per axis, rad²) the covariance's diagonal; None: not given


def covariance_of(covariance: object) -> tuple[float, float] | None:
    """(x and y's mean variance, yaw's) from a PoseWithCovariance's row-major 6 × 6 covariance; None where it says
    nothing: all zero (ROS's "unknown"), or any of the three negative or not finite."""
    values = [float(covariance[index]) for index in (0, 7, 35)]  # type: ignore[index]
    if not all(math.isfinite(value) and value >= 0.0 for value in values) or not any(values):
        return None
    return 0.5 * (values[0] + values[1]), values[2]


def decode_pose(payload: bytes, typename: str, distribution: str = "jazzy") -> RosPose:
    """The planar pose of an Odometry or PoseWithCovarianceStamped message; BadRosMessage if the bytes
    are not one, or the pose is not finite or its quaternion not a rotation."""
    try:
        message = typestore(distribution).deserialize_cdr(payload, typename)
    except Exception as error:  # rosbags raises several kinds on truncated or foreign bytes
        raise BadRosMessage(f"not a {typename}: {error}") from error
    pose = message.pose.pose  # Odometry.pose and PoseWithCovarianceStamped.pose are PoseWithCovariance
    q = pose.orientation
    values = (pose.position.x, pose.position.y, q.x, q.y, q.z, q.w)
    if not all(abs(value) < float("inf") for value in values):
        raise BadRosMessage(f"{typename} holds a non-finite pose")
    norm = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w
    if not 0.5 < norm < 1.5:
        raise BadRosMessage(f"{typename} holds an orientation that is not a unit quaternion (|q|² = {norm:.3g})")
    stamp = message.header.stamp
    theta = yaw_of_quaternion(q.x, q.y, q.z, q.w)
    return RosPose(
        (float(pose.position.x), float(pose.position.y), theta),
        message.header.frame_id,
        stamp.sec * 1_000_000_000 + stamp.nanosec,
        covariance_of(message.pose.covariance),
    )


def decode_velocity(payload: bytes, typename: str, distribution: str = "jazzy") -> tuple[float, float]:
    """(linear.x, angular.z) of a Twist or TwistStamped; BadRosMessage if the bytes are not one or either is not
    finite (a base ignores such a command: it never moves on it)."""
    try:
        message = typestore(distribution).deserialize_cdr(payload, typename)
    except Exception as error:  # rosbags raises several kinds on truncated or foreign bytes
        raise BadRosMessage(f"not a {typename}: {error}") from error
    twist = message.twist if typename == TWIST_STAMPED else message
    linear, angular = float(twist.linear.x), float(twist.angular.z)
    if not (math.isfinite(linear) and math.isfinite(angular)):
        raise BadRosMessage(f"{typename} holds a velocity that is not finite ({linear!r}, {angular!r})")
    return linear, angular


def encode_pose(
    typename: str,
    pose: Pose,
    stamp_ns: int,
    frame_id: str,
    velocity: tuple[float, float] = (0.0, 0.0),
    sigma: tuple[float, float] = (0.0, 0.0),
    distribution: str = "jazzy",
) -> bytes:
    """A planar pose as an Odometry (with its twist ``velocity``, m/s and rad/s, child frame base_link) or a
    PoseWithCovarianceStamped; ``sigma`` (position σ in metres, heading σ in radians) fills the covariance's
    diagonal (x, y, yaw)."""
    store = typestore(distribution)
    types = store.types
    x, y, theta = pose
    seconds, nanoseconds = divmod(int(stamp_ns), 1_000_000_000)
    header = types["std_msgs/msg/Header"](
        stamp=types["builtin_interfaces/msg/Time"](sec=seconds, nanosec=nanoseconds), frame_id=frame_id
    )
    covariance = np.zeros(36)
    covariance[[0, 7]], covariance[35] = sigma[0] ** 2, sigma[1] ** 2
    with_covariance = types["geometry_msgs/msg/PoseWithCovariance"](
        pose=types["geometry_msgs/msg/Pose"](
            position=types["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=0.0),
            orientation=types["geometry_msgs/msg/Quaternion"](
                x=0.0, y=0.0, z=math.sin(theta / 2.0), w=math.cos(theta / 2.0)
            ),
        ),
        covariance=covariance,
    )
    if typename == POSE_WITH_COVARIANCE:
        message = types[POSE_WITH_COVARIANCE](header=header, pose=with_covariance)
        return bytes(store.serialize_cdr(message, POSE_WITH_COVARIANCE))
    vector = types["geometry_msgs/msg/Vector3"]
    twist = types["geometry_msgs/msg/Twist"](
        linear=vector(x=float(velocity[0]), y=0.0, z=0.0), angular=vector(x=0.0, y=0.0, z=float(velocity[1]))
    )
    message = types[ODOMETRY](
        header=header,
        child_frame_id="base_link",
        pose=with_covariance,
        twist=types["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=np.zeros(36)),
    )
    return bytes(store.serialize_cdr(message, ODOMETRY))
