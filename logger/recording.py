"""Rerun recordings of a run: the map, the agents, the blobs, the errors, the events.

One :class:`RunRecorder` serves both the logger process (live, message by
message) and ``anicov run`` (after the run, from its result), so a recording
looks the same however the run was made.

**Frames.** Every point is logged in the map's own frame (what a user reads off
RViz; the model's frame without a map): poses, wedges, trails, objectives and
blobs in map units, as trajectory.csv has them. Images keep their pixels, and
a static transform on ``world/map`` and ``world/blobs/segmentation`` places
them in that frame, turned with the map's yaw. The view's y axis points down,
so each of ``world/domain``, ``world/agents`` and ``world/blobs/objectives``
carries a static y flip: the map is drawn with y up, and a hovered point
shows its map-frame value. Entity tree:

    world/domain                       LineStrips2D   the domain outline
    world/map/lack_of_coverage         Image (f32)    Υ (eq. 4): white = uncovered, black = covered
    world/map/occupancy                Image (RGBA)   terrain only: walls (brown), free cells nobody can see (blue)
    world/map/priority                 Image (f32)    priority maps only: Λ*(x)/Λ*_max (hidden at first)
    world/blobs/segmentation           SegmentationImage  blob π_j of each cell (Alg. 1)
    world/blobs/objectives             Points2D       Ψ (Alg. 1)
    world/agents/<i>/position          Points2D       labelled "agent i"
    world/agents/<i>/heading           Arrows2D
    world/agents/<i>/wedge             LineStrips2D   the camera's footprint (eq. 2)
    world/agents/<i>/trail             LineStrips2D   the last TRAIL_STEPS of its path
    world/agents/<i>/objective         LineStrips2D   agent → its objective (Alg. 2)
    world/agents/<i>/body              Ellipses2D     robots with a body: the disk of robot_radius, red
                                                      while the safety filter changes its command
    agents/<i>/safety_filter           Scalars        1 while the filter changes or stops the command, else 0
    metrics/e_D                        Scalars        eq. 5 (Fig. 4)
    agents/<i>/e_omega, v, omega       Scalars        eq. 6, 15, 16 (Fig. 5)
    bus/<role>-<id>/bytes_in, bytes_out  Scalars      over the bus only: each process's bytes per wall
                                                      second (its Traffic reports, one a second)
    run/scenario                       TextDocument   scenario, seed, team size (static)
    run/events                         TextLog        joined, left, done
    run/bandwidth                      TextDocument   over the bus only: each process's bytes in total and a second

Timelines: ``step`` (sequence) and ``sim_time`` (duration, one second per
simulated time unit).
"""

from __future__ import annotations

import math
import socket
from collections import deque
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from model.paper.fixed_point import COVERAGE_SCALE
from model.safety.safety import DEADLOCK_FOUND, DEADLOCK_RESOLVED
from model.safety.safety_record import ACTIVE as FILTER_ACTIVE
from model.scenario import Scenario
from model.scenario.map_fit import MapFrame
from model.world.world import map_frame_of, world_of

APPLICATION_ID = "anicov"
TRAIL_STEPS = 500
"""Steps of path shown behind each agent (subsampled at the map decimation)."""
WEDGE_ARC_POINTS = 9
HEADING_ARROW = 0.5
"""The heading arrow's length, in camera ranges R."""
Y_UP = rr.Transform3D(mat3x3=np.diag([1.0, -1.0, 1.0]))
"""The view's y axis points down; this draws a map-frame point with y up."""


def pixels_to_view(frame: MapFrame, rows: int, cell: float) -> rr.Transform3D:
    """Where a map view image (a grid of ``rows`` rows of ``cell``, flipped so that row 0 is the top) lies:
    pixel (u, v) is the model's point (u·cell, (rows − v)·cell), placed in the map's frame by ``frame`` and
    flipped to the view's y down, as :data:`Y_UP` flips the points. An affine map, read off where ``frame``
    puts pixel (0, 0) and one pixel along each axis."""
    xs, ys = frame.to_map(np.array([0.0, cell, 0.0]), np.full(3, rows * cell) - np.array([0.0, 0.0, cell]))
    origin, along_u, along_v = np.stack([xs, -ys], axis=1)
    matrix = np.eye(3)
    matrix[:2, 0], matrix[:2, 1] = along_u - origin, along_v - origin
    return rr.Transform3D(translation=[origin[0], origin[1], 0.0], mat3x3=matrix)


def default_blueprint(agents: int) -> rrb.Blueprint:
    """The map view beside the time series of Fig. 4 and 5."""
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial2DView(origin="/world", name="Coverage map"),
            rrb.Vertical(
                rrb.TimeSeriesView(origin="/metrics", name="e_D (Fig. 4)"),
                rrb.TimeSeriesView(origin="/agents", contents="/agents/*/v", name="v per agent (Fig. 5)"),
                rrb.TimeSeriesView(origin="/agents", contents="/agents/*/omega", name="ω per agent (Fig. 5)"),
                rrb.TimeSeriesView(origin="/agents", contents="/agents/*/e_omega", name="e_Ω per agent"),
                rrb.TimeSeriesView(origin="/bus", name="bytes per second per process"),
            ),
            column_shares=[3, 2],
        ),
        rrb.TimePanel(expanded=False),
        collapse_panels=agents > 50,
    )


class RunRecorder:
    """Writes one run to a rerun recording (a file, a live viewer, or both)."""

    def __init__(
        self,
        scenario: Scenario,
        recording_id: str,
        path: Path | None = None,
        spawn_viewer: bool = False,
        serve_web: bool = False,
        map_every: int = 50,
        web_port: int = 9090,
        grpc_port: int = 9876,
    ) -> None:
        self.scenario = scenario
        self.rows, self.cols = scenario.grid_shape
        self.frame = map_frame_of(scenario)
        self.map_every = max(1, map_every)
        self.stream = rr.RecordingStream(APPLICATION_ID, recording_id=recording_id, send_properties=False)
        sinks: list = []
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)
            sinks.append(rr.FileSink(str(path)))
        server = rr.GrpcServerSink(port=grpc_port) if serve_web else None
        if server is not None:
            sinks.append(server)  # a sink beside the file: set_sinks replaces, so all go in one call
        if spawn_viewer:
            self.stream.spawn(connect=False)
            sinks.append(rr.GrpcSink())
        if sinks:
            self.stream.set_sinks(*sinks)
        if server is not None:
            # The browser connects to the gRPC server itself: name this host, not the 0.0.0.0 it binds.
            uri = server.uri.replace("0.0.0.0", socket.gethostname())
            rr.serve_web_viewer(web_port=web_port, connect_to=uri, open_browser=False)
            print(f"rerun web viewer: http://{socket.gethostname()}:{web_port}/?url={uri}", flush=True)
        self.stream.send_blueprint(default_blueprint(scenario.agents))
        self._trails: list[deque[tuple[float, float]]] = [
            deque(maxlen=TRAIL_STEPS // self.map_every + 1) for _ in range(scenario.agents)
        ]
        self._pending: dict[int, list[tuple[int, float, float, float, float, float, float]]] = {}
        self._pending_errors: list[tuple[int, float]] = []
        self._log_static()

    # -------------------------------------------------------------- helpers

    def to_map(self, x: np.ndarray | float, y: np.ndarray | float) -> np.ndarray:
        """Model (x, y) → the map's frame, as points (…, 2)."""
        return np.stack(self.frame.to_map(np.asarray(x, dtype=float), np.asarray(y, dtype=float)), axis=-1)

    def _at(self, step: int) -> None:
        self.stream.set_time("step", sequence=step)
        self.stream.set_time("sim_time", duration=step * self.scenario.dt)

    def _log_static(self) -> None:
        width, height = self.scenario.domain
        for entity in ("world/domain", "world/agents", "world/blobs/objectives"):
            self.stream.log(entity, Y_UP, static=True)
        images = pixels_to_view(self.frame, self.rows, self.scenario.cell)
        for entity in ("world/map", "world/blobs/segmentation"):
            self.stream.log(entity, images, static=True)
        corners = self.to_map(np.array([0, width, width, 0, 0]), np.array([0, 0, height, height, 0]))
        self.stream.log("world/domain", rr.LineStrips2D([corners], colors=[(80, 80, 255)]), static=True)
        self._log_terrain()
        lines = [f"- **{key}**: {value}" for key, value in self.scenario.to_dict().items()]
        self.stream.log(
            "run/scenario", rr.TextDocument("\n".join(["# Scenario", *lines]), media_type="text/markdown"), static=True
        )
        for agent in range(self.scenario.agents):
            for name in ("v", "omega", "e_omega"):
                self.stream.log(f"agents/{agent}/{name}", rr.SeriesLines(names=f"agent {agent}"), static=True)

    def _log_terrain(self) -> None:
        """The occupancy map over Υ (its free cells transparent) and the priority map under it."""
        world = world_of(self.scenario)
        if not world.open:
            layers = np.zeros((*world.occupied.shape, 4), dtype=np.uint8)
            layers[world.occupied] = (115, 70, 25, 255)
            layers[~world.occupied & ~world.coverable] = (50, 100, 230, 140)
            self.stream.log(
                "world/map/occupancy", rr.Image(np.flipud(layers), color_model="RGBA", draw_order=1.0), static=True
            )
        if self.scenario.priority_map:
            target = round(self.scenario.lambda_star * COVERAGE_SCALE)
            priority = (world.targets / target).astype(np.float32)
            self.stream.log(
                "world/map/priority", rr.Image(np.flipud(priority), color_model="L", draw_order=-1.0), static=True
            )

    def wedge(self, x: float, y: float, theta: float) -> np.ndarray:
        """Outline of the camera footprint of eq. 2: apex, arc of radius R over ±F, back to the apex."""
        angles = np.linspace(theta - self.scenario.half_angle, theta + self.scenario.half_angle, WEDGE_ARC_POINTS)
        xs = np.concatenate([[x], x + self.scenario.range * np.cos(angles), [x]])
        ys = np.concatenate([[y], y + self.scenario.range * np.sin(angles), [y]])
        return self.to_map(xs, ys)

    # -------------------------------------------------------------- logging

    def event(self, step: int, text: str, level: str = "INFO") -> None:
        self._at(step)
        self.stream.log("run/events", rr.TextLog(text, level=level))

    def state(
        self,
        agent: int,
        step: int,
        x: float,
        y: float,
        theta: float,
        v: float,
        omega: float,
        e_omega: float,
        safety: int = 0,
    ) -> None:
        """One agent's step (``safety``: the filter's flags, model.safety.safety); buffered and sent in columns
        (cheap), drawn fully on map steps. Deadlocks found and resolved go to the events."""
        self._pending.setdefault(agent, []).append((step, x, y, theta, v, omega, e_omega, safety))
        if safety & DEADLOCK_FOUND:
            self.event(step, f"agent {agent}: held by a teammate, keeping right", "WARN")
        if safety & DEADLOCK_RESOLVED:
            self.event(step, f"agent {agent}: deadlock resolved")
        if step % self.map_every == 0:
            self._trails[agent].append((x, y))
            self._at(step)
            trail = np.array(self._trails[agent])
            self.stream.log(f"world/agents/{agent}/wedge", rr.LineStrips2D([self.wedge(x, y, theta)]))
            self.stream.log(f"world/agents/{agent}/trail", rr.LineStrips2D([self.to_map(trail[:, 0], trail[:, 1])]))

    def flush_states(self) -> None:
        """Send the buffered per-step poses and series as columns."""
        for agent, rows in self._pending.items():
            if not rows:
                continue
            data = np.array(rows)
            steps = data[:, 0].astype(np.int64)
            indexes = [
                rr.TimeColumn("step", sequence=steps),
                rr.TimeColumn("sim_time", duration=steps * self.scenario.dt),
            ]
            points = self.to_map(data[:, 1], data[:, 2])
            label = f"agent {agent}"
            self.stream.send_columns(
                f"world/agents/{agent}/position",
                indexes=indexes,
                columns=rr.Points2D.columns(positions=points, labels=[label] * len(steps)),
            )
            theta = self.frame.heading_to_map(data[:, 3])
            heading = np.stack([np.cos(theta), np.sin(theta)], axis=1) * HEADING_ARROW * self.scenario.range
            self.stream.send_columns(
                f"world/agents/{agent}/heading",
                indexes=indexes,
                columns=rr.Arrows2D.columns(origins=points, vectors=heading),
            )
            for column, name in ((4, "v"), (5, "omega"), (6, "e_omega")):
                self.stream.send_columns(
                    f"agents/{agent}/{name}", indexes=indexes, columns=rr.Scalars.columns(scalars=data[:, column])
                )
            if self.scenario.robot_radius > 0.0:
                self._send_bodies(agent, indexes, points, data[:, 7].astype(np.int64))
        self._pending = {}
        if self._pending_errors:
            data = np.array(self._pending_errors)
            self.domain_errors(data[:, 1], data[:, 0].astype(np.int64))
            self._pending_errors = []

    def truth(self, true_poses: np.ndarray, believed: np.ndarray) -> None:
        """physics = "mujoco": each robot's true position beside the believed one (``world/truth/<i>``, orange),
        and how far apart they are (``truth/<i>/error``)."""
        steps = np.arange(len(true_poses), dtype=np.int64)
        indexes = [rr.TimeColumn("step", sequence=steps), rr.TimeColumn("sim_time", duration=steps * self.scenario.dt)]
        for agent in range(true_poses.shape[1]):
            points = self.to_map(true_poses[:, agent, 0], true_poses[:, agent, 1])
            columns = rr.Points2D.columns(positions=points, colors=np.tile([255, 160, 0, 255], (len(steps), 1)))
            self.stream.send_columns(f"world/truth/{agent}/position", indexes=indexes, columns=columns)
            error = np.hypot(*(true_poses[:, agent, :2] - believed[:, agent, :2]).T)
            self.stream.send_columns(f"truth/{agent}/error", indexes=indexes, columns=rr.Scalars.columns(scalars=error))

    def _send_bodies(self, agent: int, indexes: list, points: np.ndarray, flags: np.ndarray) -> None:
        """The robot's disk at every step, red while the safety filter acts; and the filter as a series."""
        active = (flags & FILTER_ACTIVE) != 0
        radius = self.scenario.robot_radius
        colors = np.where(active[:, None], np.array([[230, 40, 40, 255]]), np.array([[200, 200, 200, 255]]))
        self.stream.send_columns(
            f"world/agents/{agent}/body",
            indexes=indexes,
            columns=rr.Ellipses2D.columns(
                centers=points, half_sizes=np.full((len(points), 2), radius), colors=colors.astype(np.uint8)
            ),
        )
        self.stream.send_columns(
            f"agents/{agent}/safety_filter", indexes=indexes, columns=rr.Scalars.columns(scalars=active.astype(float))
        )

    def domain_error(self, step: int, value: float) -> None:
        """e_D after ``step`` steps; buffered, sent with the states."""
        self._pending_errors.append((step, value))

    def domain_errors(self, errors: np.ndarray, steps: np.ndarray | None = None) -> None:
        """A series of e_D, one per step (from step 0 unless ``steps`` are given)."""
        steps = np.arange(len(errors), dtype=np.int64) if steps is None else steps
        self.stream.send_columns(
            "metrics/e_D",
            indexes=[
                rr.TimeColumn("step", sequence=steps),
                rr.TimeColumn("sim_time", duration=steps * self.scenario.dt),
            ],
            columns=rr.Scalars.columns(scalars=errors),
        )

    def traffic(self, step: int, process: str, bytes_in_per_second: float, bytes_out_per_second: float) -> None:
        """One process's bytes per wall second since its previous report (``process``: e.g. agent-2)."""
        self._at(step)
        self.stream.log(f"bus/{process}/bytes_in", rr.Scalars(bytes_in_per_second))
        self.stream.log(f"bus/{process}/bytes_out", rr.Scalars(bytes_out_per_second))

    def bandwidth_table(self, step: int, bandwidth: dict[str, dict[str, float]]) -> None:
        """Each process's totals and rates, as TeamLogger.bandwidth gives them."""
        self._at(step)
        lines = ["| process | seconds | bytes out | bytes in | out B/s | in B/s |", "|---|---|---|---|---|---|"]
        for process, row in bandwidth.items():
            lines.append(
                f"| {process} | {row['seconds']:.1f} | {row['bytes_out']} | {row['bytes_in']} | "
                f"{row['bytes_out_per_second']:.0f} | {row['bytes_in_per_second']:.0f} |"
            )
        self.stream.log(
            "run/bandwidth", rr.TextDocument("\n".join(["# Bandwidth", *lines]), media_type="text/markdown")
        )

    def lack_map(self, step: int, lack: np.ndarray) -> None:
        """Υ over the grid, flipped so that y points up in the view."""
        self._at(step)
        self.stream.log("world/map/lack_of_coverage", rr.Image(np.flipud(lack).astype(np.float32), color_model="L"))

    def objectives(
        self,
        step: int,
        positions: np.ndarray,
        members: tuple[int, ...],
        targets: np.ndarray,
        blobs: np.ndarray,
        labels: np.ndarray | None,
    ) -> None:
        self._at(step)
        if len(blobs):
            self.stream.log(
                "world/blobs/objectives",
                rr.Points2D(
                    self.to_map(blobs[:, 0], blobs[:, 1]), radii=1.2 * self.scenario.cell, colors=[(255, 160, 0)]
                ),
            )
        if labels is not None:
            self.stream.log("world/blobs/segmentation", rr.SegmentationImage(np.flipud(labels)))
        for agent, target in zip(members, targets, strict=True):
            if agent < len(positions) and not math.isnan(positions[agent][0]):
                segment = self.to_map(
                    np.array([positions[agent][0], target[0]]), np.array([positions[agent][1], target[1]])
                )
                self.stream.log(f"world/agents/{agent}/objective", rr.LineStrips2D([segment], colors=[(255, 160, 0)]))

    def close(self) -> None:
        self.flush_states()
        self.stream.flush()
        self.stream.disconnect()


def record_result(result, path: Path, recording_id: str, map_every: int = 50) -> None:
    """Write a finished in-process run (``anicov run``) as a recording."""
    recorder = RunRecorder(result.scenario, recording_id, path=path, map_every=map_every)
    trace = result.trace
    flags = result.safety_flags
    for step in range(len(trace) - 1):
        for agent in range(result.scenario.agents):
            safety = int(flags[step, agent]) if flags is not None and step < len(flags) else 0
            recorder.state(agent, step, *trace[step, agent], safety=safety)
    for plan in result.plans:
        step, members, targets, blobs, labels = plan
        recorder.objectives(step, trace[min(step, len(trace) - 1), :, :2], members, targets, blobs, labels)
    for time, snapshot in zip(result.snapshot_times, result.snapshots, strict=True):
        recorder.lack_map(round(time / result.scenario.dt), snapshot / 255.0)  # 8-bit snapshots
    recorder.lack_map(result.steps, result.final_lack)
    recorder.domain_errors(result.errors)
    if result.true_poses is not None and len(result.trace) == result.steps + 1 and len(result.true_poses) == len(trace):
        recorder.truth(result.true_poses, trace[:, :, :3])
    frame = map_frame_of(result.scenario)
    for stall in result.stalls:
        recorder.event(round(stall.time / result.scenario.dt), stall.line(result.scenario.cell, frame), level="WARN")
    recorder.event(result.steps, "run complete" if result.completed else "run stopped at max_time")
    recorder.close()
