"""A real ROS 2 base behind :class:`agents.robot.Robot`, reached over Zenoh without ROS installed here.

Two routes: zenoh-bridge-ros2dds on the robot (a topic ``/bot1/cmd_vel`` is the Zenoh key
``bot1/cmd_vel``, the payload raw CDR) or rmw_zenoh, ROS 2's own Zenoh middleware (a key with the type
name and hash, and an attachment). CDR is encoded and decoded by rosbags' typestore (:mod:`.messages`);
keys and attachments are :mod:`.transport`; frames and units :mod:`.frames`; the driver :mod:`.driver`.
rosbags is the optional extra ``anicov[ros2]``: without it, :func:`require_rosbags` says what to install.
"""

from __future__ import annotations

INSTALL_HINT = "--robot ros2 needs the ROS 2 extra: pip install 'anicov[ros2]' (it adds rosbags, for CDR)"


class Ros2Unavailable(ValueError):
    """rosbags is not installed: the message says, in one line, what to install."""


def require_rosbags() -> None:
    try:
        import rosbags.typesys  # noqa: F401
    except ImportError as error:
        raise Ros2Unavailable(INSTALL_HINT) from error
