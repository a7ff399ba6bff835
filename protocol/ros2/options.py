"""How to reach one ROS 2 base: its topics and their types, the frames, its limits (metres, radians, s).

Plain data, built from the ``--ros-*`` flags by :func:`agents.ros2.arguments.ros2_options_from`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from protocol.ros2.frames import Pose

TWIST = "geometry_msgs/msg/Twist"
TWIST_STAMPED = "geometry_msgs/msg/TwistStamped"
ODOMETRY = "nav_msgs/msg/Odometry"
POSE_WITH_COVARIANCE = "geometry_msgs/msg/PoseWithCovarianceStamped"


@dataclass(frozen=True)
class Ros2Options:
    """How to reach one base: its topics, their types, the frames, and its limits (metres, radians, s)."""

    namespace: str = ""
    transport: str = "bridge"  # "bridge" (zenoh-bridge-ros2dds) or "rmw-zenoh"
    command_topic: str = "cmd_vel"
    stamped: bool = False  # TwistStamped (newer Nav2 bases) instead of Twist
    frame_id: str = "base_link"  # TwistStamped's header frame
    odometry_topic: str = "odom"  # nav_msgs/Odometry: motion, and whether the pose is fresh
    localiser_topic: str | None = None  # PoseWithCovarianceStamped in the map frame (e.g. amcl_pose)
    odom_offset: Pose = (0.0, 0.0, 0.0)  # map ← odom (x, y metres, θ radians) without a localiser
    pose_timeout: float = 0.5
    max_linear: float = math.inf
    max_angular: float = math.inf
    domain_id: int = 0
    distribution: str = "jazzy"
    connect: tuple[str, ...] = ()  # endpoints of the robot's bridge or router, if not the team's bus
    origin: tuple[float, float] | None = None  # map-frame (x, y) of the scenario's (0, 0); None: see frame_of
    sim_time: bool = False  # the base is anicov sim's, on the team's clock (ROS's use_sim_time)
    lockstep: bool = False  # the team's clock; with sim_time each step waits for the next simulated instant

    @property
    def command_typename(self) -> str:
        return TWIST_STAMPED if self.stamped else TWIST
