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
KERNEL_FOLDERS = ("model",)
KERNEL_FILES = ("anicov/engine.py",)
"""Every .py file under these folders, and these files, keys the cache: a kernel moved to a new module (as
model/ was split by concern) is covered without a list to keep up to date. The list of files it replaced
still named model/*.py after the split, so no edit to a kernel changed the key."""


def kernel_sources() -> list[Path]:
    """The files whose bytes key the cache, in a fixed order."""
    found = {path for folder in KERNEL_FOLDERS for path in (ROOT / folder).rglob("*.py")}
    found |= {ROOT / name for name in KERNEL_FILES}
    return sorted(found)


def kernel_cache_dir() -> Path:
    digest = hashlib.sha256()
    for path in kernel_sources():
        digest.update(path.relative_to(ROOT).as_posix().encode())
        digest.update(path.read_bytes())
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
