"""The in-process engine: a whole team on one map, no bus, the same control code as the agents.

One step k (time t_k = k·dt), the same in the engine and over Zenoh in lockstep:

1. every ``replan_steps`` steps the coordinator's part runs on the map and
   poses at t_k: Algorithm 1 (objectives) then Algorithm 2 (assignment);
2. every agent decides (v, ω) from the map Λ_k, its pose and its objective;
3. every agent senses at its pose: Λ_{k+1} = Λ_k + Σ_i α_i·dt (eq. 3);
4. every agent moves by eq. 1.

The run ends when no cell is left uncovered (or at ``max_time``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import numpy as np
from numba import njit
from numba.typed import List

from anicov.plugin_engine import advance_plugin_team
from anicov.radio_engine import run_ranged
from anicov.run_parts import Snapshots, finish_run, objective_fields
from model.controllers import controller_of, law_of, law_parameters
from model.controllers.interface import Pilot
from model.paper.coverage_map import CoverageMap, add_window
from model.parameters import coverage_map_of, safety_parameters, starting_poses
from model.planning import watched_planner
from model.run import TRACE_FIELDS, ProgressCallback, RunResult, quantised_lack, snapshot_steps
from model.safety.safety import MEMORY_SIZE, SafetyParameters, filter_command
from model.scenario import Scenario
from model.step import LawParameters, decide_and_sense, move, sense_only
from model.world.ground import Ground, open_ground
from model.world.world import world_of


@njit(cache=True)
def advance_team(
    coverage: np.ndarray,
    poses: np.ndarray,
    objectives: np.ndarray,
    law: LawParameters,
    ground: Ground,
    fields: np.ndarray,
    safety: SafetyParameters,
    memory: np.ndarray,
    looks: np.ndarray,
    first_step: int,
    steps: int,
    uncovered: int,
    deficit: int,
    total_deficit: int,
    trace: np.ndarray,
    errors: np.ndarray,
    flags: np.ndarray,
) -> tuple[int, int, int]:
    """Up to ``steps`` steps of a compiled law for the whole team, stopping at full coverage. ``fields[i]``: the distance field of agent i's objective (terrain only). With ``safety`` enabled every
    command passes through the filter (model.safety.safety), from the poses at t_k, with ``memory`` (N, MEMORY_SIZE) its
    deadlock state; ``looks`` (N, 2): what each robot looked at in the step before, kept between calls too.
    Writes the per-step trace (TRACE_FIELDS), the filter's flags and e_D; returns (steps done, uncovered, deficit).
    """
    agents = poses.shape[0]
    positions = np.empty((agents, 2))
    fresh, teammates = np.zeros(agents), np.zeros(agents, dtype=np.int64)  # lockstep: every pose is t_k's
    for step in range(steps):
        positions[:, :] = poses[:, :2]
        windows = List()
        for i in range(agents):
            x, y, theta = poses[i, 0], poses[i, 1], poses[i, 2]
            v, omega, e_omega, row0, col0, ticks = decide_and_sense(
                coverage, x, y, theta, objectives[i, 0], objectives[i, 1], law, ground, fields[i], positions, i,
                looks[i],
            )  # fmt: skip
            windows.append((row0, col0, ticks))
            if safety.enabled:
                v, omega, flags[step, i] = filter_command(
                    v, omega, i, poses, fresh, teammates, ground, law.cell, safety, memory[i]
                )
            trace[step, i, 0] = x
            trace[step, i, 1] = y
            trace[step, i, 2] = theta
            trace[step, i, 3] = v
            trace[step, i, 4] = omega
            trace[step, i, 5] = e_omega
        for window in windows:
            removed, covered = add_window(coverage, window[0], window[1], window[2], law.target_ticks)
            deficit -= removed
            uncovered -= covered
        for i in range(agents):
            poses[i, 0], poses[i, 1], poses[i, 2] = move(
                poses[i, 0], poses[i, 1], poses[i, 2], trace[step, i, 3], trace[step, i, 4], law, ground
            )
        errors[step] = deficit / total_deficit
        if uncovered == 0:
            return step + 1, uncovered, deficit
    return steps, uncovered, deficit


def run_scenario(
    scenario: Scenario,
    poses: np.ndarray | None = None,
    record_trace: bool = True,
    progress: ProgressCallback | None = None,
) -> RunResult:
    """Run one team to full coverage or ``max_time`` in this process."""
    coverage_map = coverage_map_of(scenario)
    poses = starting_poses(scenario) if poses is None else np.array(poses, dtype=np.float64)
    controller = controller_of(scenario)
    advance = advance_team if controller.compiled else functools.partial(advance_plugin_team, controller, scenario)
    elsewhere = _another_engine(scenario, coverage_map, poses, advance, record_trace, progress)
    if elsewhere is not None:
        return elsewhere
    law, world = law_of(controller, scenario, coverage_map.target_ticks), world_of(scenario)
    safety, memory = safety_parameters(scenario), np.zeros((scenario.agents, MEMORY_SIZE), dtype=np.int64)
    looks = np.full((scenario.agents, 2), np.nan)  # nothing looked at yet (model.step.no_look)
    planner, block = watched_planner(scenario, controller.planner(scenario)), controller.plan_steps(scenario)
    agents, traces = scenario.agents, []
    errors: list[np.ndarray] = [np.array([coverage_map.domain_error()])]
    snapshots = Snapshots.start(coverage_map)
    scratch_trace = np.zeros((block, agents, len(TRACE_FIELDS)))
    scratch_errors = np.zeros(block)
    scratch_flags = np.zeros((block, agents), dtype=np.uint8)
    flags, plans, steps_done = [], [], 0
    while steps_done < scenario.max_steps and not coverage_map.complete:
        lack = coverage_map.lack_of_coverage()
        if planner.only_given_up_left(lack):
            break  # the watchdog gave up every cell left (model.watchdog); the coordinator stops here too
        objectives = planner.plan(steps_done * scenario.dt, lack, poses[:, :2])
        if record_trace:
            plans.append(planner.planner.record(steps_done, objectives))
        steps = min(block, scenario.max_steps - steps_done)
        done, coverage_map.uncovered_cells, coverage_map.deficit_ticks = advance(
            coverage_map.coverage, poses, objectives, law, world.ground, objective_fields(world, objectives),
            safety, memory, looks, steps_done, steps, coverage_map.uncovered_cells, coverage_map.deficit_ticks,
            coverage_map.target_ticks * coverage_map.counted_cells, scratch_trace, scratch_errors, scratch_flags,
        )  # fmt: skip
        flags.append(scratch_flags[:done].copy())
        if record_trace:
            traces.append(scratch_trace[:done].copy())
        else:
            traces.append(np.abs(scratch_trace[:done, :, 3]).sum(axis=0)[None, :, None] * np.ones((1, 1, 1)))
        errors.append(scratch_errors[:done].copy())
        steps_done += done
        now = steps_done * scenario.dt
        snapshots.take_if_due(now, coverage_map)
        if progress is not None:
            progress(now, coverage_map.domain_error())
    result = finish_run(
        scenario, coverage_map, poses, traces, errors, steps_done, snapshots.times, snapshots.lacks, record_trace
    )
    result.plans, result.stalls, result.given_up = plans, list(planner.stalls), planner.given_up()
    result.safety_flags = np.concatenate(flags) if flags else np.zeros((0, agents), dtype=np.uint8)
    return result


def _another_engine(
    scenario: Scenario,
    coverage_map: CoverageMap,
    poses: np.ndarray,
    advance: Callable[..., tuple[int, int, int]],
    record_trace: bool,
    progress: ProgressCallback | None,
) -> RunResult | None:
    """The run, where another engine makes it: paths planned once (the zig-zags), a limited radio or local
    planning (:mod:`anicov.radio_engine`), a physics world (:mod:`anicov.physics_engine`); else None."""
    if (pilots := controller_of(scenario).pilots(scenario, poses)) is not None:
        return _run_pilots(scenario, coverage_map, poses, pilots, record_trace, progress)
    if math.isfinite(scenario.comm_range) or scenario.planning == "local":
        return run_ranged(scenario, coverage_map, poses, record_trace, progress)
    if scenario.physics == "mujoco":
        from anicov.physics_engine import run_physics  # imports MuJoCo: only where a run asks for it

        return run_physics(scenario, coverage_map, poses, advance, record_trace, progress)
    return None


def _run_pilots(
    scenario: Scenario,
    coverage_map: CoverageMap,
    poses: np.ndarray,
    pilots: list[Pilot],
    record_trace: bool,
    progress: ProgressCallback | None,
) -> RunResult:
    """Paths planned once for the team (the zig-zags): each agent flies its own; the run lasts until every
    pilot is done."""
    law = law_parameters(scenario, coverage_map)
    ground, nobody = open_ground(), np.zeros((0, 2))
    rows_out: list[np.ndarray] = []
    errors = [coverage_map.domain_error()]
    snapshot_times, snapshots = [0.0], [quantised_lack(coverage_map.lack_of_coverage())]
    completion_step: int | None = None
    step = 0
    while step < scenario.max_steps and not all(pilot.finished for pilot in pilots):
        row = np.zeros((scenario.agents, len(TRACE_FIELDS)))
        for i, pilot in enumerate(pilots):
            v, omega = pilot.velocities(*poses[i])
            row[i] = (*poses[i], v, omega, 0.0)
        windows = [sense_only(coverage_map.coverage, *poses[i], law, ground, nobody, i) for i in range(scenario.agents)]
        for window in windows:
            coverage_map.add(*window)
        for i in range(scenario.agents):
            poses[i] = move(*poses[i], row[i, 3], row[i, 4], law, ground)
        rows_out.append(row)
        errors.append(coverage_map.domain_error())
        step += 1
        if coverage_map.complete and completion_step is None:
            completion_step = step
        if step % snapshot_steps(scenario.dt) == 0:
            snapshot_times.append(step * scenario.dt)
            snapshots.append(quantised_lack(coverage_map.lack_of_coverage()))
            if progress is not None:
                progress(step * scenario.dt, coverage_map.domain_error())
    plan_time = step * scenario.dt if all(pilot.finished for pilot in pilots) else None
    trace = np.stack(rows_out) if rows_out else np.zeros((0, scenario.agents, len(TRACE_FIELDS)))
    snapshot_times.append(step * scenario.dt)
    snapshots.append(quantised_lack(coverage_map.lack_of_coverage()))
    chunks = [trace] if record_trace else [np.abs(trace[:, :, 3]).sum(axis=0)[None, :, None]]
    return finish_run(
        scenario,
        coverage_map,
        poses,
        chunks,
        [np.array(errors)],
        step,
        snapshot_times,
        snapshots,
        record_trace,
        plan_time,
        completion_step,
    )
