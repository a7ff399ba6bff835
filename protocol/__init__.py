"""The team protocol: key expressions, validated messages, the replicated coverage map."""

from protocol import numba_cache  # noqa: F401  (before any kernel is compiled)
