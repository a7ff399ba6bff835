"""The in-process engine with robots in a physics world (issue 37, ``physics = "mujoco"``).

The same step as :mod:`anicov.engine` (the controller decides from the poses at t_k, the filter checks the
command, the deltas are added), one step at a time; then, in place of eq. 1, one MuJoCo world
(:class:`model.physics.world.PhysicsWorld`) drives every robot's wheels at its command for the period and
gives the poses of t_{k+1}. The plans come every ``plan_steps`` as in the engine. The contacts the world
counted are the run's ``physical_contacts`` (summary.json).

With ``[noise]`` (:mod:`model.physics.noise`) the robots decide, sense and filter from what they believe of
their poses, and their commands reach the wheels late. The truth is kept beside the belief: the true poses
(``truth.csv``), and the coverage their cameras really gave, by the same sensor rule from the true poses, on a
map of its own; ``true_coverage`` is its share of the coverable cells at Λ* when the team declared the run
complete, ``true_cells_short`` what it left.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from anicov.run_parts import Snapshots, finish_run, objective_fields
from model.controllers import controller_of, law_of
from model.paper.coverage_map import CoverageMap
from model.parameters import safety_parameters
from model.physics.noise import Belief, noise_of
from model.physics.team import PhysicalTeam
from model.planning import watched_planner
from model.run import TRACE_FIELDS, ProgressCallback, RunResult
from model.safety.safety import MEMORY_SIZE
from model.scenario import Scenario
from model.world.world import world_of


def run_physics(
    scenario: Scenario,
    coverage_map: CoverageMap,
    poses: np.ndarray,
    advance: Callable[..., tuple[int, int, int]],
    record_trace: bool,
    progress: ProgressCallback | None,
) -> RunResult:
    """One team to full coverage or ``max_time``, its robots moved by the physics world; ``advance`` is the
    engine's step (:func:`anicov.engine.advance_team`, or a plug-in's), taken one step at a time."""
    controller = controller_of(scenario)
    law, world = law_of(controller, scenario, coverage_map.target_ticks), world_of(scenario)
    safety, memory = safety_parameters(scenario), np.zeros((scenario.agents, MEMORY_SIZE), dtype=np.int64)
    looks = np.full((scenario.agents, 2), np.nan)
    planner, block = watched_planner(scenario, controller.planner(scenario)), controller.plan_steps(scenario)
    team = PhysicalTeam(scenario, poses, world.ground)
    poses[:] = team.truth  # the start poses as the world holds them (read back through its quaternions)
    belief = Belief(noise_of(scenario), team.truth, scenario.seed)
    agents = scenario.agents
    trace, errors_now = np.zeros((1, agents, len(TRACE_FIELDS))), np.zeros(1)
    flags_now = np.zeros((1, agents), dtype=np.uint8)
    rows, flags, errors = [], [], [np.array([coverage_map.domain_error()])]
    snapshots = Snapshots.start(coverage_map)
    plans, step = [], 0
    objectives = fields = None
    while step < scenario.max_steps and not coverage_map.complete:
        if step % block == 0:
            lack = coverage_map.lack_of_coverage()
            if planner.only_given_up_left(lack):
                break
            objectives = planner.plan(step * scenario.dt, lack, poses[:, :2])
            fields = objective_fields(world, objectives)
            if record_trace:
                plans.append(planner.planner.record(step, objectives))
        _, coverage_map.uncovered_cells, coverage_map.deficit_ticks = advance(
            coverage_map.coverage, poses, objectives, law, world.ground, fields, safety, memory, looks, step, 1,
            coverage_map.uncovered_cells, coverage_map.deficit_ticks,
            coverage_map.target_ticks * coverage_map.counted_cells, trace, errors_now, flags_now,
        )  # fmt: skip
        poses[:] = belief.update(team.move(trace[0, :, 3:5], law, world.ground))  # believed, from the world's
        rows.append(trace.copy() if record_trace else np.abs(trace[:, :, 3]).reshape(1, agents, 1))
        flags.append(flags_now.copy())
        errors.append(errors_now.copy())
        step += 1
        if snapshots.take_if_due(step * scenario.dt, coverage_map) and progress is not None:
            progress(step * scenario.dt, coverage_map.domain_error())
    traces = rows if record_trace else [np.concatenate(rows).sum(axis=0)[None]] if rows else []
    result = finish_run(
        scenario, coverage_map, poses, traces, errors, step, snapshots.times, snapshots.lacks, record_trace
    )
    result.plans, result.stalls, result.given_up = plans, list(planner.stalls), planner.given_up()
    result.safety_flags = np.concatenate(flags) if flags else np.zeros((0, agents), dtype=np.uint8)
    result.physics, result.true_poses = team.figures(), np.stack(team.true_poses)
    return result
