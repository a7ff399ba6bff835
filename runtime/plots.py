"""PNG figures of one run, after the paper's Fig. 4 (e_D), Fig. 5 (v, ω) and Fig. 6 (Υ maps)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle
from matplotlib.transforms import Affine2D, Transform

from model.run import RunResult
from model.scenario import Scenario
from model.world.world import map_frame_of, world_of


def plot_domain_error(result: RunResult, path: Path) -> None:
    """Fig. 4: evolution of the normalised coverage error e_D(t)."""
    times = np.arange(len(result.errors)) * result.scenario.dt
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(times, result.errors, color="black")
    ax.set_xlabel("time")
    ax.set_ylabel("$e_D$")
    ax.set_ylim(0.0, 1.02)
    ax.set_title("Domain coverage error (Fig. 4)")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_velocities(result: RunResult, path: Path) -> None:
    """Fig. 5: linear (solid) and angular (dotted) velocity of each agent."""
    trace = result.trace[:-1]
    times = np.arange(len(trace)) * result.scenario.dt
    agents = min(result.scenario.agents, 8)
    fig, axes = plt.subplots(agents, 1, figsize=(7, 1.4 * agents + 0.8), sharex=True, squeeze=False)
    for agent in range(agents):
        ax = axes[agent, 0]
        ax.plot(times, trace[:, agent, 3], color="tab:blue", linewidth=0.8, label="v")
        ax.plot(times, trace[:, agent, 4], color="tab:red", linewidth=0.8, linestyle=":", label="ω")
        ax.set_ylabel(f"agent {agent}")
        ax.grid(alpha=0.3)
    axes[0, 0].legend(loc="upper right", fontsize=8)
    axes[0, 0].set_title("Motion actions (Fig. 5)" + ("" if agents == result.scenario.agents else " — first 8 agents"))
    axes[-1, 0].set_xlabel("time")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_coverage_maps(result: RunResult, path: Path) -> None:
    """Fig. 6: lack of coverage Υ at four times, with the trajectories so far (and the walls, on a terrain).
    With a map, in the map's own frame (as trajectory.csv: the model's placed at the fitted map's corner and
    turned by its yaw)."""
    scenario = result.scenario
    width, height = scenario.domain
    frame = map_frame_of(scenario)
    box = (0.0, width, 0.0, height)  # the model's domain, placed in the map's frame by each axes' transform
    outline_x, outline_y = frame.to_map(
        np.array([0.0, width, width, 0.0, 0.0]), np.array([0.0, 0.0, height, height, 0.0])
    )
    low_x, high_x, low_y, high_y = outline_x.min(), outline_x.max(), outline_y.min(), outline_y.max()
    last = len(result.snapshots) - 1
    picks = sorted({round(last * fraction) for fraction in (0.25, 0.5, 0.75, 1.0)})
    fig, axes = plt.subplots(1, len(picks), figsize=(3.3 * len(picks), 3.6), squeeze=False)
    for ax, pick in zip(axes[0], picks, strict=True):
        time = result.snapshot_times[pick]
        placed = Affine2D().rotate(frame.yaw).translate(*frame.corner) + ax.transData
        shown = result.snapshots[pick] / 255.0
        ax.imshow(shown, origin="lower", extent=box, cmap="gray_r", vmin=0.0, vmax=1.0, transform=placed)
        draw_obstacles(ax, scenario, box, placed)
        upto = min(round(time / scenario.dt) + 1, len(result.trace))
        for agent in range(scenario.agents):
            xs, ys = frame.to_map(result.trace[:upto, agent, 0], result.trace[:upto, agent, 1])
            (line,) = ax.plot(xs, ys, linewidth=0.6)
            if scenario.robot_radius > 0.0:  # the robot's disk, to scale (issue 12)
                ax.add_patch(
                    Circle((xs[-1], ys[-1]), scenario.robot_radius, fill=False, color=line.get_color(), linewidth=0.8)
                )
            else:
                ax.plot(xs[-1], ys[-1], "o", markersize=5, mfc="none", color=line.get_color())
        ax.plot(outline_x, outline_y, "k--", linewidth=0.8)
        ax.set_xlim(low_x - 0.1 * (high_x - low_x), high_x + 0.1 * (high_x - low_x))
        ax.set_ylim(low_y - 0.1 * (high_y - low_y), high_y + 0.1 * (high_y - low_y))
        ax.set_aspect("equal")
        ax.set_title(f"t = {time:.0f}")
        if scenario.map:
            ax.set_xlabel("x, map frame")
    fig.suptitle("Lack of coverage Υ (black: uncovered) and trajectories (Fig. 6)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def draw_obstacles(
    ax: plt.Axes, scenario: Scenario, box: tuple[float, float, float, float], placed: Transform | None = None
) -> None:
    """Occupied cells in brown, and free cells nobody can see hatched (nothing, in the open world), over
    ``box`` (left, right, bottom, top), placed by the transform ``placed`` (default: the axes' data)."""
    world = world_of(scenario)
    if world.open:
        return
    layers = np.zeros((*world.occupied.shape, 4))
    layers[world.occupied] = (0.45, 0.27, 0.1, 1.0)
    layers[~world.occupied & ~world.coverable] = (0.2, 0.4, 0.9, 0.55)
    ax.imshow(layers, origin="lower", extent=box, interpolation="nearest", transform=placed or ax.transData)


def plot_truth(result: RunResult, path: Path) -> None:
    """physics = "mujoco" with noise: each robot's true path (solid) beside its believed one (dashed), and how
    far apart they were over time."""
    assert result.true_poses is not None
    truth, believed = result.true_poses, result.trace[: len(result.true_poses), :, :3]
    times = np.arange(len(truth)) * result.scenario.dt
    figure, (paths, gaps) = plt.subplots(1, 2, figsize=(12, 5))
    for agent in range(truth.shape[1]):
        line = paths.plot(truth[:, agent, 0], truth[:, agent, 1], linewidth=0.8, label=f"agent {agent}, true")[0]
        paths.plot(believed[:, agent, 0], believed[:, agent, 1], "--", color=line.get_color(), linewidth=0.8)
        gaps.plot(times, np.hypot(*(truth[:, agent, :2] - believed[:, agent, :2]).T), linewidth=0.6)
    paths.set(title="true paths (solid) and believed (dashed)", xlabel="x", ylabel="y", aspect="equal")
    paths.legend(fontsize="small")
    gaps.set(title="belief off the truth", xlabel="t", ylabel="distance")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def write_run_plots(result: RunResult, out_dir: Path) -> list[Path]:
    """The figures of a run into ``out_dir`` (and, with physics, belief against truth); returns their paths."""
    paths = [out_dir / "error.png", out_dir / "velocities.png", out_dir / "coverage_maps.png"]
    plot_domain_error(result, paths[0])
    plot_velocities(result, paths[1])
    plot_coverage_maps(result, paths[2])
    if (
        result.true_poses is not None
        and len(result.trace) == result.steps + 1
        and len(result.trace) == len(result.true_poses)
    ):
        paths.append(out_dir / "truth.png")
        plot_truth(result, paths[-1])
    return paths
