"""Opening the bus: a Zenoh config from flags or a file (multicast scouting off), a session that waits
for its router, and the publisher every team message goes out on."""

from __future__ import annotations

import argparse
import json
import logging
import time

import zenoh

log = logging.getLogger("anicov.bus")

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"


def zenoh_config(
    mode: str = "client",
    connect: list[str] | None = None,
    listen: list[str] | None = None,
    config_file: str | None = None,
) -> zenoh.Config:
    """A Zenoh config: from a JSON5 file if given, else built from flags; multicast scouting off.

    Endpoints are explicit so that parallel teams (and parallel tests) never
    discover each other.
    """
    config = zenoh.Config.from_file(config_file) if config_file else zenoh.Config()
    if not config_file:
        config.insert_json5("mode", json.dumps(mode))
        config.insert_json5("scouting/multicast/enabled", "false")
        # Nothing to discover with multicast off: do not wait for it (a router opens 0.5 s sooner).
        config.insert_json5("scouting/delay", "0")
        # Loopback links of a single host: a lost peer is noticed within the lease.
    if connect:
        config.insert_json5("connect/endpoints", json.dumps(connect))
    if listen:
        config.insert_json5("listen/endpoints", json.dumps(listen))
    return config


class RouterUnreachable(RuntimeError):
    """No session could be opened within the patience given (the router is down, or refuses us)."""


def open_session(config: zenoh.Config, patience: float = 30.0, delay: float = 0.25) -> zenoh.Session:
    """Open a session, retrying while the router is not up yet (a robot may boot before it)."""
    deadline = time.monotonic() + patience
    while True:
        try:
            return zenoh.open(config)
        except zenoh.ZError as error:
            if time.monotonic() >= deadline:
                raise RouterUnreachable(f"no Zenoh session after {patience:.0f} s of retries: {error}") from error
            log.debug("zenoh open failed (%s), retrying", error)
            time.sleep(delay)


def team_publisher(session: zenoh.Session, key: str) -> zenoh.Publisher:
    """A publisher for team traffic: reliable, never dropped under congestion (lockstep would
    wait forever for a dropped delta), and express (sent at once, not batched: a step waits on it)."""
    return session.declare_publisher(
        key,
        congestion_control=zenoh.CongestionControl.BLOCK,
        reliability=zenoh.Reliability.RELIABLE,
        express=True,
    )


def config_from_arguments(args: argparse.Namespace) -> zenoh.Config:
    """The config a team process's flags ask for (runtime.arguments.add_process_arguments)."""
    return zenoh_config(args.mode, connect=args.connect, listen=args.listen, config_file=args.zenoh_config)


def logger_listens(session: zenoh.Session, alive_key: str, timeout: float) -> bool:
    """A logger's liveliness token (``alive_key``: TeamKeys.alive("logger")) is up: it declares it once it
    is subscribed and agrees with the team, so a run started after this has all of it recorded."""
    return any(reply.ok is not None for reply in session.liveliness().get(alive_key, timeout=timeout))
