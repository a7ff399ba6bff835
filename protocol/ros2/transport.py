"""Where a ROS 2 topic lives on Zenoh, for the two routes to a base.

- ``bridge``: zenoh-bridge-ros2dds maps the ROS topic ``/bot1/cmd_vel`` to the Zenoh key
  ``bot1/cmd_vel`` (the topic name without its leading slash); the payload is the DDS sample as
  serialized, CDR with its 4-byte encapsulation header; no attachment.
- ``rmw-zenoh``: ROS 2's Zenoh middleware keys a topic's data as
  ``<domain id>/<topic name without leading slash>/<DDS type name>/<RIHS01 type hash>``, and every
  sample carries an attachment: the publisher's sequence number (int64), its source timestamp (int64
  nanoseconds) and its 16-byte GID, serialized by zenoh-cpp's ``ext::Serializer`` (rmw_zenoh_cpp
  ``AttachmentData::serialize_to_zbytes``; little endian, the GID a ``std::array`` and so a sequence
  behind its LEB128 length, 1 byte): 8 + 8 + 1 + 16 = 33 bytes. zenoh-python's ``zenoh.ext`` follows
  the same serialization spec, so it writes them here. See RMW_ZENOH_RELEASES.
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import zenoh.ext

from protocol.ros2.messages import dds_type_name, type_hash
from protocol.ros2.options import ODOMETRY, POSE_WITH_COVARIANCE

if TYPE_CHECKING:
    from protocol.ros2.options import Ros2Options

TRANSPORTS = ("bridge", "rmw-zenoh")
GID_SIZE = 16
RMW_ZENOH_RELEASES = "rmw_zenoh_cpp 0.2.x (jazzy), 0.6.x (kilted) and rolling: the 33-byte attachment above"
"""The releases whose attachment this writes. Earlier sources (rmw_zenoh on zenoh-c's serializer, 2024)
put each field behind its name as a string ("sequence_number", ...): those are not supported, and an
rmw_zenoh that does not read the attachment drops the sample (see deploy/ros2.md)."""


def topic_name(namespace: str, topic: str) -> str:
    """The fully qualified topic name without its leading slash: ``bot1`` + ``cmd_vel`` → ``bot1/cmd_vel``.
    A topic given absolute (``/cmd_vel``) ignores the namespace, as ROS 2 resolves it."""
    if topic.startswith("/"):
        return topic.strip("/")
    return "/".join(part for part in (namespace.strip("/"), topic.strip("/")) if part)


def bridge_key(namespace: str, topic: str) -> str:
    return topic_name(namespace, topic)


def rmw_zenoh_key(domain_id: int, namespace: str, topic: str, typename: str, distribution: str = "jazzy") -> str:
    return f"{domain_id}/{topic_name(namespace, topic)}/{dds_type_name(typename)}/{type_hash(typename, distribution)}"


def rmw_zenoh_attachment(sequence: int, timestamp_ns: int, gid: bytes) -> bytes:
    """rmw_zenoh's per-sample attachment (33 bytes): int64 sequence, int64 timestamp, uint8 length, GID."""
    if len(gid) != GID_SIZE:
        raise ValueError(f"a GID has {GID_SIZE} bytes, got {len(gid)}")
    serialized = zenoh.ext.z_serialize((zenoh.ext.Int64(sequence), zenoh.ext.Int64(timestamp_ns), bytes(gid)))
    return serialized.to_bytes()


def publisher_gid(key: str, salt: str) -> bytes:
    """A stable 16-byte GID for this process's publisher (rmw_zenoh takes any 16 bytes unique per publisher)."""
    return hashlib.blake2b(f"{key}|{salt}".encode(), digest_size=GID_SIZE).digest()


@dataclass(frozen=True)
class Ros2Topics:
    """The keys of one base's topics on Zenoh (command, odometry, the localiser's pose if any), and what
    goes with each command."""

    transport: str
    command_key: str
    odometry_key: str
    localiser_key: str | None = None
    gid: bytes = b""

    @staticmethod
    def of(options: Ros2Options) -> Ros2Topics:
        if options.transport not in TRANSPORTS:
            raise ValueError(f"--ros-transport: expected one of {', '.join(TRANSPORTS)}, got {options.transport!r}")
        topics = [
            (options.command_topic, options.command_typename),
            (options.odometry_topic, ODOMETRY),
            (options.localiser_topic, POSE_WITH_COVARIANCE),
        ]
        if options.transport == "bridge":
            keys = [bridge_key(options.namespace, topic) if topic else None for topic, _ in topics]
            return Ros2Topics("bridge", keys[0] or "", keys[1] or "", keys[2])
        keys = [
            rmw_zenoh_key(options.domain_id, options.namespace, topic, typename, options.distribution)
            if topic
            else None
            for topic, typename in topics
        ]
        gid = publisher_gid(keys[0] or "", f"{time.time_ns()}")
        return Ros2Topics("rmw-zenoh", keys[0] or "", keys[1] or "", keys[2], gid)

    def attachment(self, sequence: int) -> bytes | None:
        """What the ``sequence``-th command carries besides its payload (None: nothing)."""
        if self.transport == "bridge":
            return None
        return rmw_zenoh_attachment(sequence, time.time_ns(), self.gid)

    def describe_pose(self) -> str:
        """Where the pose comes from, for the 'waiting for a pose' line."""
        text = f"{ODOMETRY} on Zenoh key {self.odometry_key}"
        if self.localiser_key:
            text += f" and {POSE_WITH_COVARIANCE} on {self.localiser_key}"
        return f"{text} ({self.transport})"
