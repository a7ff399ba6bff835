"""A real ROS 2 base behind :class:`agents.robot.Robot`, reached over Zenoh without ROS installed here.

Two routes: zenoh-bridge-ros2dds on the robot (a topic ``/bot1/cmd_vel`` is the Zenoh key
``bot1/cmd_vel``, the payload raw CDR) or rmw_zenoh, ROS 2's own Zenoh middleware (a key with the type
name and hash, and an attachment). The wire is protocol/ros2's, shared with the simulator process: CDR by
rosbags' typestore (:mod:`protocol.ros2.messages`), keys and attachments (:mod:`protocol.ros2.transport`),
frames and units (:mod:`protocol.ros2.frames`). Here: the driver (:mod:`.driver`) and its flags.
rosbags is the optional extra ``anicov[ros2]``: without it, :func:`require_rosbags` says what to install.
"""

from __future__ import annotations

from protocol.ros2 import INSTALL_HINT, Ros2Unavailable, require_rosbags

__all__ = ["INSTALL_HINT", "Ros2Unavailable", "require_rosbags"]
