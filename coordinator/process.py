"""The coordinator process: Algorithms 1–2 for the team, membership, snapshots, the end of the run.

A thin shell: the decisions are :class:`coordinator.node.Coordinator`'s, the loop's turns are
:class:`coordinator.stepping.Stepping`'s. It waits for every agent's hello (or rebuilds a running
team, replacing a coordinator that died), steps the run on either clock, announces its end and
writes the run directory (trajectory.csv, summary.json, plots) as ``anicov run`` does, so a team
spread over hosts, where no launcher runs, still leaves one.
"""

from __future__ import annotations

import logging
import os

import zenoh

from coordinator.ending import announce_end, await_loggers, settle_last_deltas, write_outputs
from coordinator.endpoints import CoordinatorBus
from coordinator.node import Coordinator, CoordinatorOptions
from coordinator.startup import gather_team, resume_running_team
from coordinator.stepping import Stepping
from model.paper.coverage_map import load_kernels as load_map_kernels
from model.radio.exact_coverage import load_kernels as load_event_kernel
from model.scenario import Scenario
from protocol.messages import RunControl
from protocol.recovery import LossTimer
from protocol.session import open_session
from protocol.traffic import TrafficReporter
from runtime.lifecycle import EXIT_FAILED, EXIT_INCOMPLETE, EXIT_OK, StopFlag, parent_is_gone, settle_garbage_collector

log = logging.getLogger("anicov.coordinator")


def run_coordinator(scenario: Scenario, options: CoordinatorOptions, config: zenoh.Config, stop: StopFlag) -> int:
    node = Coordinator(scenario, options)
    parent = os.getppid()
    with open_session(config) as session:
        bus = CoordinatorBus.declare(session, node)
        traffic = TrafficReporter(session, bus.keys.traffic("coordinator"), "coordinator", 0, bus.traffic).start()
        try:
            loss = LossTimer()  # from here, as before: the first step's patience includes the start
            settle_garbage_collector()
            load_map_kernels()  # while the agents start, not in step 0
            load_event_kernel(node.limits.kernel)
            found = gather_team(bus, options.await_logger, stop, parent)
            step = 0
            if found.running:
                step = resume_running_team(bus, found)
            elif len(node.positions) < scenario.agents or not found.logger_ready:
                missing = "" if found.logger_ready else " and no logger appeared"
                log.error("only %d of %d agents said hello%s; giving up", len(node.positions), scenario.agents, missing)
                bus.announce(RunControl("abort", 0, reason="agents missing at start"))
                traffic.stop()
                bus.token.undeclare()
                return stop.exit_code(EXIT_FAILED)
            else:
                node.members = set(range(scenario.agents))
                log.info("all %d agents present; starting (%s clock)", scenario.agents, options.clock)
                node.take_snapshot(0.0)
            stepping = Stepping(bus, options.speed, step, loss=loss)
            stepping.first_message(resumed=bool(found.running))
            turn = stepping.lockstep_turn if node.lockstep else stepping.realtime_turn
            while stepping.outcome is None and not stop.stopped:
                if parent_is_gone(parent):
                    stop.set()
                    break
                turn()
                if stepping.outcome is None or node.lockstep:
                    stepping.status_if_due()
            done = announce_end(bus, stepping)
            settle_last_deltas(bus, done, lambda: stop.stopped or parent_is_gone(parent))
            traffic.stop()
            bus.token.undeclare()
            write_outputs(bus, stepping, step if found.running else None, options.out)
            await_loggers(bus, lambda: stop.stopped or parent_is_gone(parent))
        finally:
            traffic.stop()  # idempotent: on an error too, its thread must not outlive the session
    if stepping.outcome is None:
        return stop.exit_code(EXIT_FAILED)
    return EXIT_OK if stepping.outcome[1] else EXIT_INCOMPLETE
