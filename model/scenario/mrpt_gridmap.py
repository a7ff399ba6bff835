"""An occupancy grid saved by MRPT (the Mobile Robot Programming Toolkit): ``*.gridmap`` or ``*.gridmap.gz``.

MRPT's SLAM applications (rbpf-slam, icp-slam) save their map as one serialized ``COccupancyGridMap2D``
object, gzip-compressed or not. The public SLAM maps that Debian's ``mrpt-common`` package ships are in this
format (``scenarios/real/README.md``). The layout read here (MRPT's ``CArchive`` object framing, class version
2 to 6; little-endian):

- ``0x80 | n``, then the class name ``COccupancyGridMap2D`` (n bytes); one byte, the class version;
- one byte, the bits per cell (8 or 16); ``size_x``, ``size_y`` (uint32); ``x_min``, ``x_max``, ``y_min``,
  ``y_max``, ``resolution`` (float32, metres);
- ``size_x × size_y`` cells (int8 or int16), row-major, row 0 at ``y_min``: the **log-odds of being free**,
  scaled by MRPT's ``LOGODD_K = 16`` (``CLogOddsGridMapLUT.h``): p(free) = 1 / (1 + exp(−cell / 16)); 0 is
  unknown (p = 0.5). The insertion options that follow the cells are not needed and not read.

A cell is then thresholded as ``map_saver`` would threshold it, on p(occupied) = 1 − p(free), with map_server's
defaults: occupied above 0.65, free below 0.196, unknown in between (not free, as for a ROS map).
"""

from __future__ import annotations

import gzip
import struct
from pathlib import Path

import numpy as np

from model.scenario.terrain import OccupancyMap, TerrainError, file_sha256

CLASS_NAME = b"COccupancyGridMap2D"
LOGODD_K = 16.0
"""MRPT's integer scale of the log-odds (CLogOddsGridMapLUT: cell = round(log-odds × 16))."""
OCCUPIED_THRESH = 0.65
FREE_THRESH = 0.196
"""map_server's default thresholds on p(occupied), as map_saver applies them."""
_HEADER = struct.Struct("<BII5f")  # bits per cell, size_x, size_y, x_min, x_max, y_min, y_max, resolution


def is_mrpt_gridmap(path: Path) -> bool:
    """Whether the file's name says MRPT grid map (``.gridmap`` or ``.gridmap.gz``)."""
    return path.name.endswith((".gridmap", ".gridmap.gz"))


def _read_bytes(path: Path) -> bytes:
    try:
        raw = path.read_bytes()
        return gzip.decompress(raw) if raw[:2] == b"\x1f\x8b" else raw
    except OSError as error:
        raise TerrainError(f"cannot read map {path}: {error}") from error
    except (EOFError, gzip.BadGzipFile) as error:
        raise TerrainError(f"map {path}: a broken gzip stream ({error})") from error


def _saved_value(single: float) -> float:
    """A float32 as the saver meant it: the shortest decimal that rounds to it (0.08, not 0.0799999982)."""
    return float(np.format_float_positional(np.float32(single), unique=True))


def load_mrpt_gridmap(path: Path) -> OccupancyMap:
    """Read an MRPT grid map (see the module's docstring); raise TerrainError naming the file on any problem."""
    data = _read_bytes(path)
    name_length = data[0] & 0x7F if data else 0
    if not data or not data[0] & 0x80 or data[1 : 1 + name_length] != CLASS_NAME:
        raise TerrainError(f"map {path}: not an MRPT grid map (expected a serialized {CLASS_NAME.decode()})")
    offset = 1 + name_length
    version = data[offset]
    if not 2 <= version <= 6:
        raise TerrainError(f"map {path}: {CLASS_NAME.decode()} version {version} is not read (versions 2 to 6 are)")
    offset += 1
    if len(data) < offset + _HEADER.size:
        raise TerrainError(f"map {path}: the file ends inside its header")
    bits, size_x, size_y, x_min, _x_max, y_min, _y_max, resolution = _HEADER.unpack_from(data, offset)
    offset += _HEADER.size
    if bits not in (8, 16):
        raise TerrainError(f"map {path}: {bits} bits per cell (expected 8 or 16)")
    if not (size_x and size_y and np.isfinite(resolution) and resolution > 0):
        raise TerrainError(f"map {path}: size {size_x} × {size_y} at resolution {resolution} is not a map")
    cell_type = np.int8 if bits == 8 else np.dtype("<i2")
    count = size_x * size_y
    if len(data) < offset + count * (bits // 8):
        raise TerrainError(f"map {path}: the file ends before its {size_x} × {size_y} cells")
    log_odds = np.frombuffer(data, dtype=cell_type, count=count, offset=offset).reshape(size_y, size_x)
    free_probability = 1.0 / (1.0 + np.exp(-log_odds.astype(np.float64) / LOGODD_K))
    occupancy = 1.0 - free_probability
    free = occupancy < FREE_THRESH
    # MRPT stores row 0 at y_min, as the model does: no flip.
    return OccupancyMap(
        occupied=~free,
        resolution=_saved_value(resolution),
        origin=(_saved_value(x_min), _saved_value(y_min)),
        path=path,
        sha256=file_sha256(path),
        known=free | (occupancy > OCCUPIED_THRESH),
    )
