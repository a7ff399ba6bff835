"""Reading a recording back, headless: what ``anicov replay --summary`` prints and tests check.

Uses ``rerun.chunk.RrdReader``: every chunk carries an entity path, its
timelines and its component columns (Arrow).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from rerun.chunk import RrdReader

_AGENT = re.compile(r"^/world/agents/(\d+)/")
_BUS = re.compile(r"^/bus/([a-z]+-\d+)/(bytes_in|bytes_out)$")


@dataclass
class RecordingContent:
    recording_ids: list[str]
    entities: set[str] = field(default_factory=set)
    timed: set[str] = field(default_factory=set)  # the entities logged on the step timeline (not only static)
    last_step: int = -1
    domain_error: dict[int, float] = field(default_factory=dict)  # step → e_D
    positions: dict[int, dict[int, tuple[float, float]]] = field(default_factory=dict)  # agent → step → map (x, y)
    maps: dict[int, np.ndarray] = field(default_factory=dict)  # step → Υ as logged (view orientation)
    traffic: dict[tuple[str, str], list[float]] = field(default_factory=dict)  # (process, bytes_in|out) → B/s
    transforms: dict[str, np.ndarray] = field(default_factory=dict)  # entity → its static 2D affine (3 × 3)

    @property
    def agents(self) -> list[int]:
        return sorted({int(m.group(1)) for entity in self.entities if (m := _AGENT.match(entity))})

    @property
    def final_domain_error(self) -> float | None:
        return self.domain_error[max(self.domain_error)] if self.domain_error else None

    def final_map(self) -> np.ndarray | None:
        """The last logged Υ, flipped back to grid orientation (row 0 at y = 0)."""
        return np.flipud(self.maps[max(self.maps)]) if self.maps else None


def summarise_recording(path: Path, load_maps: bool = True) -> RecordingContent:
    reader = RrdReader(str(path))
    content = RecordingContent([entry.recording_id for entry in reader.recordings()])
    for chunk in reader.stream():
        entity = str(chunk.entity_path)
        content.entities.add(entity)
        if chunk.is_static:
            _read_transform(content, entity, chunk.to_record_batch())
            continue
        if "step" not in chunk.timeline_names:
            continue
        content.timed.add(entity)
        batch = chunk.to_record_batch()
        steps = batch.column("step").to_numpy()
        if len(steps):
            content.last_step = max(content.last_step, int(steps.max()))
        if entity == "/metrics/e_D":
            values = batch.column("Scalars:scalars").to_pylist()
            content.domain_error.update({int(s): float(v[0]) for s, v in zip(steps, values, strict=True)})
        elif entity.endswith("/position") and (match := _AGENT.match(entity)):
            agent = int(match.group(1))
            points = batch.column("Points2D:positions").to_pylist()
            content.positions.setdefault(agent, {}).update(
                {int(s): (float(p[0][0]), float(p[0][1])) for s, p in zip(steps, points, strict=True)}
            )
        elif match := _BUS.match(entity):
            values = batch.column("Scalars:scalars").to_pylist()
            content.traffic.setdefault((match.group(1), match.group(2)), []).extend(float(v[0]) for v in values)
        elif entity == "/world/map/lack_of_coverage" and load_maps:
            buffers = batch.column("Image:buffer").to_pylist()
            formats = batch.column("Image:format").to_pylist()
            for step, buffer, image_format in zip(steps, buffers, formats, strict=True):
                fmt = image_format[0]
                data = np.frombuffer(bytes(buffer[0]), dtype=np.float32)
                content.maps[int(step)] = data.reshape(fmt["height"], fmt["width"])
    return content


def _read_transform(content: RecordingContent, entity: str, batch) -> None:
    """A static Transform3D of the map view, as the 2D affine it is: view = A · (x, y, 1)."""
    names = set(batch.schema.names)
    if "Transform3D:mat3x3" not in names:
        return
    matrix = np.array(batch.column("Transform3D:mat3x3").to_pylist()[-1][0], dtype=float).reshape(3, 3, order="F")
    translation = (
        batch.column("Transform3D:translation").to_pylist()[-1] if "Transform3D:translation" in names else None
    )
    affine = np.eye(3)
    affine[:2, :2] = matrix[:2, :2]
    if translation:
        affine[:2, 2] = np.array(translation[0], dtype=float)[:2]
    content.transforms[entity] = affine


def format_recording_summary(content: RecordingContent) -> str:
    lines = [
        f"recording id(s)  {', '.join(content.recording_ids)}",
        f"steps            0 .. {content.last_step}",
        f"agents           {len(content.agents)} ({', '.join(map(str, content.agents[:12]))}"
        + (" ..." if len(content.agents) > 12 else "")
        + ")",
        "final e_D        " + ("-" if content.final_domain_error is None else f"{content.final_domain_error:.6f}"),
        f"maps logged      {len(content.maps)}",
    ]
    for process in sorted({process for process, _ in content.traffic}):
        mean = {
            direction: float(np.mean(values)) if (values := content.traffic.get((process, direction))) else 0.0
            for direction in ("bytes_out", "bytes_in")
        }
        lines.append(
            f"bus {process:<12} out {mean['bytes_out']:.0f} B/s, in {mean['bytes_in']:.0f} B/s (mean of reports)"
        )
    lines.append(f"entities         {len(content.entities)}")
    shown = sorted(entity for entity in content.entities if not _AGENT.match(entity) or "/0/" in entity)
    lines += [f"  {entity}" for entity in shown]
    if len(content.agents) > 1:
        lines.append("  (world/agents/<i>/... likewise for every agent)")
    return "\n".join(lines)
