"""What a run leaves behind: trajectory.csv, summary.json, the counters and the one-screen summary.

Numbers are written with Python's shortest round-trip ``repr``, so the same
run gives byte-identical files and a reader recovers the exact floats.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from model.paper.fixed_point import COVERAGE_SCALE
from model.paper.metrics import optimum_time, total_sensing_ability
from model.planning import default_patience
from model.run import RunResult
from model.safety.safety_record import safety_figures
from model.scenario.map_fit import MapFrame
from model.watchdog import rounded
from model.world.world import World, map_frame_of, world_of

TRAJECTORY_HEADER = "t,agent,x,y,theta,v,omega"


def step_time(step: int, dt: float) -> float:
    """t_k = k·dt, rounded to 9 decimals so that 0.1·3 prints as 0.3."""
    return round(step * dt, 9)


def write_trajectory(result: RunResult, path: Path) -> None:
    """One row per agent per step (pose at the start, (v, ω) during), then the final poses with v = ω = 0.
    On a map, positions are in the map's own frame (what RViz shows): the model's, plus where its (0, 0)
    lies, and headings turned by its yaw (:func:`model.world.world.map_frame_of`; nothing changes in the map
    frame's own)."""
    dt = result.scenario.dt
    frame = map_frame_of(result.scenario)
    shifted = frame != MapFrame()
    lines = [TRAJECTORY_HEADER]
    for step, rows in enumerate(result.trace):
        t = repr(step_time(step, dt))
        for agent, (x, y, theta, v, omega, _) in enumerate(rows.tolist()):
            if x != x:  # NaN: a realtime run that never heard this agent's state for this step
                continue
            if shifted:
                (x, y), theta = frame.to_map(x, y), float(frame.heading_to_map(theta))
            lines.append(f"{t},{agent},{x!r},{y!r},{theta!r},{v!r},{omega!r}")
    path.write_text("\n".join(lines) + "\n", encoding="ascii")


TRUTH_HEADER = "t,agent,x,y,theta,x_believed,y_believed,theta_believed"


def write_truth(result: RunResult, path: Path) -> None:
    """physics = "mujoco": one row per agent per step, the true pose beside the believed one (the trace's), in
    the map's frame like trajectory.csv."""
    assert result.true_poses is not None
    frame = map_frame_of(result.scenario)
    lines = [TRUTH_HEADER]
    for step, (truths, rows) in enumerate(zip(result.true_poses, result.trace, strict=False)):
        t = repr(step_time(step, result.scenario.dt))
        for agent, ((x, y, theta), believed) in enumerate(zip(truths.tolist(), rows[:, :3].tolist(), strict=True)):
            (x, y), theta = frame.to_map(x, y), float(frame.heading_to_map(theta))
            (bx, by), btheta = frame.to_map(believed[0], believed[1]), float(frame.heading_to_map(believed[2]))
            lines.append(f"{t},{agent},{x!r},{y!r},{theta!r},{bx!r},{by!r},{btheta!r}")
    path.write_text("\n".join(lines) + "\n", encoding="ascii")


def summary_of(result: RunResult) -> dict[str, Any]:
    """The summary.json fields (see README)."""
    scenario = result.scenario
    world = world_of(scenario)
    ability = total_sensing_ability(scenario.range, scenario.half_angle, scenario.alpha_max)
    optimum = optimum_time(covered_area(world), scenario.lambda_star, ability, scenario.agents)
    paths = result.path_lengths
    completion = result.completion_time if result.completed else None
    summary: dict[str, Any] = {
        "scenario": scenario.to_dict(),
        "completed": result.completed,
        "completion_time": completion,
        "steps": result.steps,
        "path_length": [float(length) for length in paths],
        "team_path_length": float(paths.sum()),
        "final_error": float(result.errors[-1]),
        "optimum_time": optimum,
        "time_ratio": completion / optimum if completion is not None else None,
    }
    if result.plan_time is not None:
        summary["plan_time"] = result.plan_time
    if not world.open or scenario.priority_map:
        summary["terrain"] = world.summary()
    if result.radio is not None:
        summary["radio"] = result.radio
    if result.physics is not None:
        for key in ("physical_contacts", "true_coverage", "true_cells_short"):
            summary[key] = result.physics[key]
        summary["physics"] = result.physics
    if result.stalls or not result.completed:
        summary["watchdog"] = watchdog_report(result, world)
    if scenario.robot_radius > 0.0 and len(result.trace) == result.steps + 1:  # filter on or off, to compare
        summary |= safety_figures(
            result.trace[:, :, :2], result.safety_flags, world.ground, scenario.cell, result.timed_positions
        )
    return summary


def watchdog_report(result: RunResult, world: World) -> dict[str, Any]:
    """What the progress watchdog (model.watchdog) did, and which cells a run that did not complete left, and
    why: given up by the watchdog (with the robots' reasons in its interventions), or time ran out. Cell
    centres in the map's frame."""
    scenario = result.scenario
    frame = map_frame_of(scenario)
    left = (result.final_lack > 0.0) & world.coverable
    given_up = result.given_up if result.given_up is not None else np.zeros_like(left)
    centres = [
        rounded(frame.to_map((col + 0.5) * scenario.cell, (row + 0.5) * scenario.cell))
        for row, col in np.argwhere(left)
    ]
    why = "completed" if result.completed else (
        "every cell left was given up by the watchdog" if left.any() and not (left & ~given_up).any()
        else "max_time reached" if result.steps >= scenario.max_steps else "the run was stopped"
    )  # fmt: skip
    return {
        "enabled": scenario.watchdog,
        "patience": (scenario.watchdog_time or default_patience(world)) if scenario.watchdog else None,
        "interventions": [stall.as_dict(scenario.cell, frame) for stall in result.stalls],
        "cells_left": int(left.sum()),
        "cells_given_up": int((left & given_up).sum()),
        "why": why,
        "cells_left_centres": centres,
    }


def covered_area(world: World) -> float:
    """The area eq. 19's t*_N needs covered to Λ*: the domain's in the open world; on a terrain the
    coverable cells' only, each weighted by its Λ*(x)/Λ* under a priority map."""
    scenario = world.scenario
    if world.open and not scenario.priority_map:
        return scenario.domain[0] * scenario.domain[1]
    target = round(scenario.lambda_star * COVERAGE_SCALE)
    return float(world.targets[world.coverable].sum()) / target * scenario.cell**2


def write_summary(summary: dict[str, Any], path: Path) -> None:
    path.write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")


def format_summary(summary: dict[str, Any], out_dir: Path | None = None) -> str:
    """A one-screen, human summary of a run."""
    scenario = summary["scenario"]
    watchdog = summary.get("watchdog")
    status = (
        "complete" if summary["completed"] else f"NOT complete ({watchdog['why'] if watchdog else 'max_time reached'})"
    )
    completion = summary["completion_time"]
    lines = [
        f"anicov run: {scenario['agents']} agent(s), controller {scenario['controller']}, seed {scenario['seed']}",
        f"  coverage        {status}, final e_D = {summary['final_error']:.4f}",
        f"  completion time {completion:.1f}" if completion is not None else "  completion time -",
        f"  optimum t*_N    {summary['optimum_time']:.1f}"
        + (f"   (ratio {summary['time_ratio']:.2f})" if summary["time_ratio"] is not None else ""),
        f"  steps           {summary['steps']} (dt = {scenario['dt']})",
        f"  team path       {summary['team_path_length']:.1f}"
        + "   per agent: "
        + ", ".join(f"{length:.0f}" for length in summary["path_length"][:8])
        + (" ..." if len(summary["path_length"]) > 8 else ""),
    ]
    terrain = summary.get("terrain")
    if terrain is not None:
        lines.append(
            f"  terrain         {terrain['occupied_cells']} occupied cells, {terrain['coverable_cells']} coverable, "
            f"{terrain['unreachable_cells']} free but unreachable (left out of e_D)"
        )
    if watchdog is not None and (watchdog["interventions"] or watchdog["cells_left"]):
        lines.append(
            f"  watchdog        {len(watchdog['interventions'])} interventions; {watchdog['cells_left']} cells left, "
            f"{watchdog['cells_given_up']} of them given up (summary.json: watchdog)"
        )
    if "min_separation" in summary:
        lines.append(_safety_line(summary))
    if "physical_contacts" in summary:
        lines.append(
            f"  physics         {summary['physical_contacts']} new contacts in the physics world; true coverage "
            f"{100 * summary['true_coverage']:.2f} % ({summary['true_cells_short']} cells short at Λ*)"
        )
    if out_dir is not None:
        lines.append(f"  outputs         {out_dir}/")
    return "\n".join(lines)


def _safety_line(summary: dict[str, Any]) -> str:
    scenario = summary["scenario"]
    radius = scenario["robot_radius"]
    separation, clearance = summary["min_separation"], summary["min_clearance"]
    filtered = "filter on" if scenario.get("safety", True) else "filter OFF"
    return (
        f"  safety          {filtered}: min separation "
        + (f"{separation:.3f} (2r = {2 * radius:g})" if separation is not None else "-")
        + ", min clearance "
        + (f"{clearance:.3f} (r = {radius:g})" if clearance is not None else "-")
        + f", active {100 * summary['filter_active_fraction']:.1f} % of steps, "
        f"deadlocks {summary['deadlocks_resolved']}/{summary['deadlocks']} resolved"
    )


def bandwidth_of(agent_counts: list[dict[str, Any]], dt: float) -> dict[str, Any] | None:
    """Bytes each robot sent and took in over the run (its counters: every payload it published or served
    to a teammate's query, and every one its inbox received), per step, per second at speed 1 (1/dt steps
    a second) and per wall second of this run; None if no agent stepped."""
    stepped = [counts for counts in agent_counts if counts.get("steps", 0) > 0]
    if not stepped:
        return None
    sent = [counts["bytes_sent"] + counts.get("bytes_served", 0) for counts in stepped]
    out = [total / counts["steps"] for total, counts in zip(sent, stepped, strict=True)]
    into = [counts["bytes_received"] / counts["steps"] for counts in stepped]
    bandwidth = {
        "agents_counted": len(stepped),
        "bytes_out_per_step": sum(out) / len(out),
        "bytes_in_per_step": sum(into) / len(into),
        "bytes_out_per_second_at_speed_1": sum(out) / len(out) / dt,
        "bytes_in_per_second_at_speed_1": sum(into) / len(into) / dt,
        "max_bytes_in_per_step": max(into),
    }
    if all(counts.get("wall_seconds", 0) > 0 for counts in stepped):
        walls = [counts["wall_seconds"] for counts in stepped]
        bandwidth["bytes_out_per_wall_second"] = sum(s / w for s, w in zip(sent, walls, strict=True)) / len(walls)
        bandwidth["bytes_in_per_wall_second"] = sum(
            counts["bytes_received"] / w for counts, w in zip(stepped, walls, strict=True)
        ) / len(walls)
    return bandwidth


def format_bandwidth(bandwidth: dict[str, Any], deltas: str) -> str:
    """The summary's line of what each robot's radio carried."""
    return (
        f"  bus per robot   out {bandwidth['bytes_out_per_step']:.0f} B, in {bandwidth['bytes_in_per_step']:.0f} B a step"
        f" (deltas as {'events' if deltas == 'event' else 'cells'}); at speed 1: out {8e-3 * bandwidth['bytes_out_per_second_at_speed_1']:.1f} kbit/s,"
        f" in {8e-3 * bandwidth['bytes_in_per_second_at_speed_1']:.1f} kbit/s"
        + (
            f"\n  bus this run    out {bandwidth['bytes_out_per_wall_second']:.0f} B/s, in "
            f"{bandwidth['bytes_in_per_wall_second']:.0f} B/s per robot (wall clock, start to end)"
            if "bytes_out_per_wall_second" in bandwidth
            else ""
        )
    )


def write_counts(path: str | Path | None, counts: dict[str, object]) -> None:
    """Persist a process's message counters (read by tests and by whoever studies a run); None: nowhere.
    Written whole or not at all (a temporary file renamed), so a process killed meanwhile leaves no half file."""
    if path:
        target = Path(path)
        partial = target.with_name(target.name + ".partial")
        partial.write_text(json.dumps(counts, indent=2, sort_keys=True) + "\n", encoding="utf-8")
        os.replace(partial, target)


def read_counts(path: Path) -> dict[str, Any] | None:
    """A process's counters, or None when it wrote none (or what is there cannot be read)."""
    try:
        counts = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return counts if isinstance(counts, dict) else None


def write_run_directory(result: RunResult, out_dir: Path, counts: dict[str, object] | None = None) -> dict[str, Any]:
    """trajectory.csv, summary.json, the plots and, from the coordinator, coordinator_counts.json: what
    ``anicov run`` and a team over the bus leave alike. Returns the summary."""
    from runtime.plots import write_run_plots

    out_dir.mkdir(parents=True, exist_ok=True)
    write_trajectory(result, out_dir / "trajectory.csv")
    if (
        result.true_poses is not None
        and len(result.trace) == result.steps + 1
        and len(result.trace) == len(result.true_poses)
    ):
        write_truth(result, out_dir / "truth.csv")
    summary = summary_of(result)
    write_summary(summary, out_dir / "summary.json")
    if counts is not None:
        write_counts(out_dir / "coordinator_counts.json", counts)
    write_run_plots(result, out_dir)
    return summary
