"""The in-process engine for a team on a radio (issue 13): one replica per robot.

The same step as :mod:`anicov.engine` (decide, sense, move with the same kernels), but each robot
decides from its *own* replica of Λ, and what reaches that replica follows :mod:`model.radio.radio`: a robot
holds its own events at once and its teammates' through contact and anti-entropy. The run ends when the
world is covered (the union of every event made), whatever each replica believes. Planning is central
(the coordinator, a base station everyone hears, plans on the union) or local (each robot on its
replica, with the teammates it hears).

With ``comm_range`` unlimited every replica equals the union at every step, and the run equals
:func:`anicov.engine.run_scenario` byte for byte, central or local (tests/test_radio_engine.py).
"""

from __future__ import annotations

import copy

import numpy as np

from anicov.run_parts import Snapshots, finish_run, objective_fields
from model.controllers import controller_of, law_parameters
from model.paper.coverage_map import CoverageMap
from model.parameters import safety_parameters
from model.planning import Plan, WatchedPlanner, watched_planner
from model.radio.radio import contacts, divergence, local_members, merge_knowledge
from model.run import TRACE_FIELDS, ProgressCallback, RunResult
from model.safety.safety import MEMORY_SIZE, SafetyParameters, filter_command
from model.scenario import Scenario
from model.step import LawParameters, decide_and_sense, move
from model.watchdog import Stall
from model.world.world import World, world_of

Window = tuple[int, int, np.ndarray]


class RadioTeam:
    """The replicas, what each knows, and every event made so far (a window per agent-step)."""

    def __init__(self, union: CoverageMap, agents: int) -> None:
        self.union = union  # every event made: the world's coverage
        self.replicas = [copy.deepcopy(union) for _ in range(agents)]
        self.knows = np.zeros((agents, agents), dtype=np.int64)  # model.radio.radio: events of j held by i
        self.events: list[list[Window]] = [[] for _ in range(agents)]
        self.divergence_sum = 0.0
        self.divergence_max = 0
        self.contact_sum = 0.0
        self.steps = 0

    def exchange(self, windows: list[Window], in_contact: np.ndarray) -> None:
        """Step k's events enter the union and their makers' replicas; contact and anti-entropy bring
        the rest (:func:`model.radio.radio.merge_knowledge`)."""
        for agent, window in enumerate(windows):
            self.events[agent].append(window)
            self.union.add(*window)
        np.fill_diagonal(self.knows, len(self.events[0]))  # a robot knows its own events at once
        learnt = merge_knowledge(self.knows, in_contact)
        np.fill_diagonal(self.knows, len(self.events[0]) - 1)  # its own window is not yet in its replica
        for receiver, maker in zip(*np.nonzero(learnt > self.knows), strict=True):
            for window in self.events[maker][self.knows[receiver, maker] : learnt[receiver, maker]]:
                self.replicas[receiver].add(*window)
        self.knows = learnt
        differing = divergence(
            [replica.coverage for replica in self.replicas], self.union.coverage, self.union.target_ticks
        )
        self.divergence_sum += float(differing.mean())
        self.divergence_max = max(self.divergence_max, int(differing.max()))
        self.contact_sum += float(in_contact.sum() - len(in_contact)) / len(in_contact)
        self.steps += 1

    def figures(self) -> dict[str, float]:
        """What summary.json reports of the radio: replica divergence (cells whose Υ differs from the
        union's, :func:`model.radio.radio.divergence`: mean over robots then over the run's steps; the most any
        robot had at any step; the mean at the end, before the final exchange leaves one map everywhere),
        and how many teammates a robot heard, on average over robots and steps."""
        steps = max(self.steps, 1)
        final = divergence(
            [replica.coverage for replica in self.replicas], self.union.coverage, self.union.target_ticks
        )
        return {
            "divergence_mean": self.divergence_sum / steps,
            "divergence_max": self.divergence_max,
            "divergence_final": float(final.mean()),
            "teammates_heard_mean": self.contact_sum / steps,
        }


def run_ranged(
    scenario: Scenario,
    coverage_map: CoverageMap,
    poses: np.ndarray,
    record_trace: bool,
    progress: ProgressCallback | None,
) -> RunResult:
    """A team whose robots hear each other only within ``comm_range``, with central or local planning."""
    law, world = law_parameters(scenario, coverage_map), world_of(scenario)
    safety, memory = safety_parameters(scenario), np.zeros((scenario.agents, MEMORY_SIZE), dtype=np.int64)
    looks = np.full((scenario.agents, 2), np.nan)  # what each robot looked at in the step before
    agents = scenario.agents
    team = RadioTeam(coverage_map, agents)
    controller = controller_of(scenario)
    # Each with its progress watchdog (model.watchdog), as the engine's and the coordinator's planner has.
    central = watched_planner(scenario, controller.planner(scenario))
    planners = [watched_planner(scenario, controller.planner(scenario)) for _ in range(agents)]
    rows, flags, errors = [], [], [coverage_map.domain_error()]
    snapshots = Snapshots.start(coverage_map)
    plans: list[Plan] = []
    objectives, fields = np.zeros((agents, 2)), np.zeros((agents, 1, 1))
    step = 0
    while step < scenario.max_steps and not coverage_map.complete:
        positions = poses[:, :2].copy()
        in_contact = contacts(positions, scenario.comm_range)
        if step % scenario.plan_steps == 0:
            if only_given_up_left(scenario, team, central, planners):
                break  # the watchdog gave up every cell left (every robot's, planning locally)
            objectives = plan_objectives(scenario, team, central, planners, positions, in_contact, step)
            fields = objective_fields(world, objectives)
            if record_trace:
                plans.append(record_plan(scenario, central, step, objectives))
        row, flag_row, windows = decide_team(
            team, poses, positions, objectives, fields, law, world, safety, memory, looks
        )
        team.exchange(windows, in_contact)
        for i in range(agents):
            poses[i] = move(*poses[i], row[i, 3], row[i, 4], law, world.ground)
        rows.append(row)
        flags.append(flag_row)
        errors.append(coverage_map.domain_error())
        step += 1
        if snapshots.take_if_due(step * scenario.dt, coverage_map) and progress is not None:
            progress(step * scenario.dt, coverage_map.domain_error())
    trace = np.stack(rows) if rows else np.zeros((0, agents, len(TRACE_FIELDS)))
    chunks = [trace] if record_trace else [np.abs(trace[:, :, 3]).sum(axis=0)[None, :, None]]
    result = finish_run(
        scenario, coverage_map, poses, chunks, [np.array(errors)], step, snapshots.times, snapshots.lacks, record_trace
    )
    result.plans = plans
    result.stalls, result.given_up = watchdog_outcome(scenario, central, planners)
    result.safety_flags = np.stack(flags) if flags else np.zeros((0, agents), dtype=np.uint8)
    result.radio = team.figures()
    return result


def decide_team(
    team: RadioTeam,
    poses: np.ndarray,
    positions: np.ndarray,
    objectives: np.ndarray,
    fields: np.ndarray,
    law: LawParameters,
    world: World,
    safety: SafetyParameters,
    memory: np.ndarray,
    looks: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, list[Window]]:
    """Every robot's step k from its own replica: the trace row (TRACE_FIELDS), the filter's flags and
    the delta windows, as :func:`anicov.engine.advance_team` makes them from the one map."""
    agents = len(poses)
    ages, kinds = np.zeros(agents), np.zeros(agents, dtype=np.int64)  # every robot sees t_k's poses
    row = np.zeros((agents, len(TRACE_FIELDS)))
    flag_row = np.zeros(agents, dtype=np.uint8)
    windows: list[Window] = []
    for i in range(agents):
        x, y, theta = poses[i]
        v, omega, e_omega, row0, col0, ticks = decide_and_sense(
            team.replicas[i].coverage, x, y, theta, objectives[i, 0], objectives[i, 1], law, world.ground,
            fields[i], positions, i, looks[i],
        )  # fmt: skip
        if safety.enabled:
            v, omega, flag_row[i] = filter_command(
                v, omega, i, poses, ages, kinds, world.ground, law.cell, safety, memory[i]
            )
        row[i] = (x, y, theta, v, omega, e_omega)
        windows.append((row0, col0, ticks))
    return row, flag_row, windows


def plan_objectives(
    scenario: Scenario,
    team: RadioTeam,
    central: WatchedPlanner,
    planners: list[WatchedPlanner],
    positions: np.ndarray,
    in_contact: np.ndarray,
    step: int,
) -> np.ndarray:
    """(N, 2): central, Algorithms 1-2 on the union for everyone; local, each robot's own objective from
    its replica and the teammates it hears (:func:`model.radio.radio.local_members`)."""
    now = step * scenario.dt
    if scenario.planning == "central":
        return central.plan(now, team.union.lack_of_coverage(), positions)
    objectives = np.zeros((len(positions), 2))
    for me, planner in enumerate(planners):
        members = local_members(me, in_contact)
        mine = planner.plan(now, team.replicas[me].lack_of_coverage(), positions[members], members)
        objectives[me] = mine[members.index(me)]
    return objectives


def only_given_up_left(
    scenario: Scenario, team: RadioTeam, central: WatchedPlanner, planners: list[WatchedPlanner]
) -> bool:
    """The run is over: central, every cell left was given up by the watchdog; local, every robot's own
    watchdog gave up every cell its replica has left (a cell left in the world is left in every replica)."""
    if scenario.planning == "central":
        return central.only_given_up_left(team.union.lack_of_coverage())
    return all(
        planner.only_given_up_left(replica.lack_of_coverage())
        for planner, replica in zip(planners, team.replicas, strict=True)
    )


def watchdog_outcome(
    scenario: Scenario, central: WatchedPlanner, planners: list[WatchedPlanner]
) -> tuple[list[Stall], np.ndarray | None]:
    """(stalls, cells given up): central, its watchdog's; local, every robot's, in time order, a stall that
    several robots' watchdogs saw alike (robots in touch plan alike) once, and the cells any of them gave up."""
    if scenario.planning == "central":
        return list(central.stalls), central.given_up()
    stalls = sorted({stall: None for planner in planners for stall in planner.stalls}, key=lambda stall: stall.time)
    given = [planner.given_up() for planner in planners if planner.given_up() is not None]
    return stalls, (np.logical_or.reduce(given) if given else None)


def record_plan(scenario: Scenario, central: WatchedPlanner, step: int, objectives: np.ndarray) -> Plan:
    """The plan as the recording keeps it; local planning has no one team's blobs to draw."""
    if scenario.planning == "central":
        return central.planner.record(step, objectives)
    return (step, tuple(range(len(objectives))), objectives.copy(), np.zeros((0, 2)), None)
