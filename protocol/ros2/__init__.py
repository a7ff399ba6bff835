"""The ROS 2 wire over Zenoh, shared by the agents' driver (agents/ros2) and the simulator (simulator/).

A base's topics and their types (:mod:`.options`), their Zenoh keys on both routes (:mod:`.transport`),
the messages as CDR by rosbags (:mod:`.messages`), and frames and units between a base and the scenario
(:mod:`.frames`). rosbags is imported only when a message is encoded or decoded: it is the optional extra
``anicov[ros2]``.
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
