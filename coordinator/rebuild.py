"""A restarted coordinator: the run rebuilt from the agents' histories, as the lost coordinator lived it.

Step by step from 0, the deltas of step s−1 enter the replica (Λ_s), e_D and the map snapshots are
logged, the states of step s are recorded and, in lockstep on a replanning step, the planner runs on
Λ_s and the poses of step s, so its memory of blobs is the one the lost coordinator had. In realtime
the plans ran on the wall clock and the paper's law keeps nothing of them worth restoring; a planner
whose plans build on each other (``TeamPlanner.replayed``: anicov's routes, cut once from the starting
poses, their progress, patches, detours and cleanups) is replayed as in lockstep, on every plan step, so
each robot goes on with the route, stops and cleanup it had, never flying covered ground again. The run
resumes at the latest step every member has published. In lockstep that step is still open (its
deltas go into the next go), so a run that lost its coordinator still equals the engine. Agents gone
before the restart left no history: their coverage is adopted from a member's snapshot.
"""

from __future__ import annotations

from coordinator.node import Coordinator
from protocol.inbox import Received
from protocol.messages import AgentState, MapDelta, Snapshot

HistoryMessages = list[MapDelta | AgentState]
"""Deltas and states read from the agents' histories, in any order."""


def by_step(
    messages: HistoryMessages, members: set[int]
) -> tuple[dict[int, list[MapDelta]], dict[int, list[AgentState]]]:
    """The members' deltas by sequence and their states (not hellos) by step."""
    deltas: dict[int, list[MapDelta]] = {}
    states: dict[int, list[AgentState]] = {}
    for message in messages:
        if isinstance(message, MapDelta) and message.agent in members:
            deltas.setdefault(message.seq, []).append(message)
        elif isinstance(message, AgentState) and message.step >= 0 and message.agent in members:
            states.setdefault(message.step, []).append(message)
    return deltas, states


def resume_step(states: dict[int, list[AgentState]], members: set[int]) -> tuple[int, set[int]]:
    """The latest step every agent that published has published, and those agents."""
    latest: dict[int, int] = {}
    for step, of_step in states.items():
        for state in of_step:
            latest[state.agent] = max(latest.get(state.agent, -1), step)
    if not latest:
        raise RuntimeError(f"the team is running but no history of agents {sorted(members)} could be read")
    return min(latest.values()), set(latest)


def rebuild(node: Coordinator, messages: HistoryMessages, members: set[int], snapshot: Snapshot | None = None) -> int:
    """Replay the histories into ``node``; return the step to resume at (see the module's docstring)."""
    deltas, states = by_step(messages, members)
    resume, publishing = resume_step(states, members)
    with node.lock:
        node.members = publishing
        replay(node, deltas, states, resume)
        gone = set(snapshot.applied) - members if snapshot is not None else set()
        if gone and snapshot is not None:
            node.replica.adopt(snapshot, [m for m in messages if isinstance(m, MapDelta)], gone)
            node.log.events.append(f"coverage of agents {sorted(gone)} taken from a member's snapshot")
        if node.lockstep:
            node.open_step = resume
        elif node.planner.replayed:
            node.log.events.append(f"plans replayed from the histories to step {resume}")
        # What lies beyond: the open step's deltas (for the next go) and any later ones.
        for message in messages:
            if isinstance(message, MapDelta) and message.seq >= resume and message.agent in members:
                node.handle_locked(Received("", message))
            elif isinstance(message, AgentState) and message.step >= resume and message.agent in members:
                node.handle_locked(Received("", message))
    return resume


def replay(
    node: Coordinator, deltas: dict[int, list[MapDelta]], states: dict[int, list[AgentState]], resume: int
) -> None:
    """Steps 0..resume as the lost coordinator lived them: Λ_s, e_D, snapshots, states, and the plans."""
    for step in range(resume + 1):
        if step > 0:
            for delta in deltas.get(step - 1, []):
                node.replica.apply(delta)
            node.log_step(step)
        else:
            node.take_snapshot(0.0)  # Υ at t_0, as a coordinator that lived the run kept it
        for state in states.get(step, []):
            node.log.record(state)
            node.positions[state.agent] = (state.pose[0], state.pose[1])
        if (node.lockstep or node.planner.replayed) and step % node.scenario.plan_steps == 0:
            node.plan(step if node.lockstep else 0)  # realtime plans as the live ones did (coordinator.stepping)
        for state in states.get(step, []):
            node.latest_state_step[state.agent] = step
            node.positions[state.agent] = (state.next_pose[0], state.next_pose[1])
