"""One robot: dynamics, wedge sensing, control law, and the agent process."""

import protocol.numba_cache  # noqa: F401  (before any kernel is compiled)
