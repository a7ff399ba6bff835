"""The model, pure, by concern (docs/architecture.md): ``scenario`` (every concern's keys), ``paper`` (the
unicycle, the sensor, the coverage map and errors, the laws, Algorithms 1–2, the metrics), ``world`` (maps,
what a wedge sees among walls, free paths), ``safety`` (the barrier filter), ``radio`` (coverage in integers),
one robot's compiled step (``step``) and ``controllers`` (one interface, the built-in ones, a user's own).

No bus, no processes, no files but the scenario's (and numba's cache of compiled kernels). Everything above
(protocol, agents, coordinator, logger, anicov) imports from here; nothing here imports from them.
"""

from model import numba_cache  # noqa: F401  (before any kernel is compiled)
