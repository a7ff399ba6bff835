"""Where numba keeps its compiled kernels: a folder keyed by the kernels' source.

numba's own cache (``cache=True``) invalidates a function when *its* file
changes, but not when a jitted function it calls, in another file, changes:
a stale inlined copy would silently survive. Keying the cache folder by a hash
of every file that holds a kernel makes any edit start from a clean cache.
``NUMBA_CACHE_DIR`` set by the user wins.
"""

from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
KERNEL_SOURCES = (
    "model/geometry.py",
    "model/sensing.py",
    "model/control.py",
    "model/dynamics.py",
    "model/step.py",
    "model/visibility.py",
    "model/clearance.py",
    "model/geodesic.py",
    "model/reachability.py",
    "model/wall_law.py",
    "model/occlusion.py",
    "model/ground.py",
    "model/safety.py",
    "model/barrier_qp.py",
    "model/safety_record.py",
    "model/fixed_point.py",
    "model/coverage_map.py",
    "anicov/engine.py",
)


def kernel_cache_dir() -> Path:
    digest = hashlib.sha256()
    for name in KERNEL_SOURCES:
        path = ROOT / name
        digest.update(name.encode())
        digest.update(path.read_bytes() if path.exists() else b"")
    return ROOT / ".numba_cache" / digest.hexdigest()[:16]


def configure() -> None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    folder = str(kernel_cache_dir())
    os.environ["NUMBA_CACHE_DIR"] = folder  # numba reads it when it is first imported
    numba = sys.modules.get("numba")
    if numba is not None:  # already imported: tell it directly (importing it here would slow every CLI start)
        numba.config.CACHE_DIR = folder


configure()
