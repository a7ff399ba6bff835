"""protocol.ros2.transport: the Zenoh keys of a ROS 2 topic on both routes, and rmw_zenoh's attachment."""

from __future__ import annotations

import struct

import pytest
import zenoh
import zenoh.ext

from protocol.ros2.options import Ros2Options
from protocol.ros2.transport import Ros2Topics, bridge_key, rmw_zenoh_attachment, topic_name

TWIST_KEY_TAIL = (
    "geometry_msgs::msg::dds_::Twist_/RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"
)


def read_attachment(attachment: bytes | None) -> tuple[int, int, bytes]:
    """As zenoh-cpp's Deserializer reads rmw_zenoh's AttachmentData (zenoh-python follows the same spec)."""
    assert attachment is not None
    return zenoh.ext.z_deserialize(tuple[zenoh.ext.Int64, zenoh.ext.Int64, bytes], zenoh.ZBytes(attachment))


@pytest.mark.parametrize(
    ("namespace", "topic", "name"),
    [
        ("bot1", "cmd_vel", "bot1/cmd_vel"),
        ("/bot1/", "odom", "bot1/odom"),
        ("", "cmd_vel", "cmd_vel"),
        ("bot1", "/cmd_vel", "cmd_vel"),
        ("fleet/bot2", "amcl_pose", "fleet/bot2/amcl_pose"),
    ],
)
def test_topic_names_resolve_as_ros_2_does(namespace, topic, name):
    assert topic_name(namespace, topic) == name
    assert bridge_key(namespace, topic) == name  # zenoh-bridge-ros2dds: the name without its leading slash


def test_bridge_route_keys_and_no_attachment():
    topics = Ros2Topics.of(Ros2Options(namespace="bot1"))
    assert (topics.command_key, topics.odometry_key, topics.localiser_key) == ("bot1/cmd_vel", "bot1/odom", None)
    localised = Ros2Topics.of(Ros2Options(namespace="bot1", localiser_topic="amcl_pose"))
    assert localised.localiser_key == "bot1/amcl_pose"
    assert topics.attachment(1) is None


def test_rmw_zenoh_keys_carry_domain_type_name_and_hash():
    topics = Ros2Topics.of(Ros2Options(namespace="robot1", transport="rmw-zenoh", domain_id=0))
    # The key rmw_zenoh's design document gives for /robot1/cmd_vel (docs/design.md, "Topic key expressions").
    assert topics.command_key == f"0/robot1/cmd_vel/{TWIST_KEY_TAIL}"
    assert topics.odometry_key.startswith("0/robot1/odom/nav_msgs::msg::dds_::Odometry_/RIHS01_")
    localised = Ros2Topics.of(Ros2Options(namespace="robot1", transport="rmw-zenoh", localiser_topic="amcl_pose"))
    assert localised.localiser_key is not None
    assert localised.localiser_key.startswith(
        "0/robot1/amcl_pose/geometry_msgs::msg::dds_::PoseWithCovarianceStamped_/RIHS01_"
    )
    stamped = Ros2Topics.of(Ros2Options(namespace="b", transport="rmw-zenoh", domain_id=7, stamped=True))
    assert stamped.command_key.startswith("7/b/cmd_vel/geometry_msgs::msg::dds_::TwistStamped_/RIHS01_")


def test_the_attachment_is_rmw_zenohs_33_bytes():
    gid = bytes(range(16))
    attachment = rmw_zenoh_attachment(42, 1_700_000_000_000_000_001, gid)
    # int64 sequence, int64 timestamp, LEB128 length 16 of the GID array, the GID (all little endian).
    assert attachment == struct.pack("<qqB", 42, 1_700_000_000_000_000_001, 16) + gid
    assert read_attachment(attachment) == (
        42,
        1_700_000_000_000_000_001,
        gid,
    )


def test_a_gid_must_have_16_bytes():
    with pytest.raises(ValueError, match="16 bytes"):
        rmw_zenoh_attachment(1, 1, b"short")


def test_each_command_of_a_publisher_has_the_next_sequence_and_the_same_gid():
    topics = Ros2Topics.of(Ros2Options(transport="rmw-zenoh"))
    first, second = (read_attachment(topics.attachment(n)) for n in (1, 2))
    assert (first[0], second[0]) == (1, 2) and first[2] == second[2] == topics.gid
    assert second[1] >= first[1]
