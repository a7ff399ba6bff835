"""A team on a radio of limited range: who hears whom, what each replica knows, who plans with whom.

The map is a grow-only sum of events (DESIGN §5), each (agent j, sequence s) applied once, so a
replica is fully described by what it knows: ``knows[i, j]`` = how many of agent j's events replica i
holds. Those are always a prefix 0 .. knows[i, j] − 1 of j's events, for the following rule keeps it so:

- **Contact** (:func:`contacts`): robots i and m hear each other during step k when their centres at
  t_k are at most ``comm_range`` apart (the receiver's filter; a robot always hears itself).
- **Anti-entropy on contact** (:func:`merge_knowledge`; Demers et al., "Epidemic algorithms for
  replicated database maintenance", PODC 1987): robots in contact exchange their per-agent sequence
  summaries and each fetches what it lacks, so after step k replica i holds, of every agent j, the most
  any robot in contact knew. One hop per step: what m learnt from a third robot at step k reaches i at
  step k + 1 at the earliest. A robot's own events are always known to it at once, and the prefix of j
  that i receives is j's whole history as some robot in contact held it, so prefixes stay prefixes.

With ``comm_range`` unlimited every robot is in contact with every other at every step, every replica
holds every event of step k at step k + 1, which is the paper's (and the lockstep bus's) team.

**Local planning** (:func:`local_members`): a robot runs Algorithms 1-2 on its own replica with the
teammates it is in contact with (their poses at t_k) and takes its own objective. Among those, Alg. 2
settles conflicts exactly as the paper's coordinator would (its order and tie-break by agent id); robots
out of contact are unknown to the plan and may pick the same objective: that conflict is the cost of
the radio, measured by the range study (docs/radio.md). With everyone in contact and identical replicas
every robot computes the central plan: the run equals the central one.
"""

from __future__ import annotations

import numpy as np


def contacts(positions: np.ndarray, comm_range: float) -> np.ndarray:
    """(N, N) bool: i and m hear each other, centres (N, 2) at most ``comm_range`` apart (inf: all)."""
    agents = len(positions)
    if not np.isfinite(comm_range):
        return np.ones((agents, agents), dtype=bool)
    gaps = positions[:, None, :] - positions[None, :, :]
    return np.hypot(gaps[..., 0], gaps[..., 1]) <= comm_range


def merge_knowledge(knows: np.ndarray, in_contact: np.ndarray) -> np.ndarray:
    """One step of anti-entropy: knows'[i, j] = max over m in contact with i (i included) of knows[m, j].

    ``knows`` (N, N) int: events of agent j held by replica i; ``in_contact`` from :func:`contacts`."""
    # (i, m, j): what m knows of j, where i hears m; −1 where it does not (every count is ≥ 0).
    heard = np.where(in_contact[:, :, None], knows[None, :, :], -1)
    return heard.max(axis=1)


def local_members(me: int, in_contact: np.ndarray) -> list[int]:
    """The robots a local planner plans for: itself and the teammates it is in contact with, by id."""
    return [int(agent) for agent in np.flatnonzero(in_contact[me])]


def divergence(replicas: list[np.ndarray], union: np.ndarray, target_ticks: int) -> np.ndarray:
    """(N,) cells whose lack of coverage Υ (eq. 4) differs between each robot's replica and the map of
    every event made so far: what the robot's control and planning read wrongly. Counts above Λ* are
    left out (a cell seen twice or three times is covered either way)."""
    truth = np.minimum(union, target_ticks)
    return np.array([int(np.count_nonzero(np.minimum(replica, target_ticks) != truth)) for replica in replicas])
