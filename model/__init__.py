"""The paper's model, pure: scenario, unicycle (eq. 1), sensing (eq. 2–3), coverage map and errors
(eq. 4–6), the laws (eq. 7–16), Algorithms 1–2, the zig-zag baseline and the metrics (eq. 18–19).

No bus, no processes, no files but the scenario's (and numba's cache of compiled kernels). Everything above (protocol, agents, coordinator,
logger, anicov) imports from here; nothing here imports from them.
"""

from model import numba_cache  # noqa: F401  (before any kernel is compiled)
