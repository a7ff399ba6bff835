"""model.world.detours: a place the team reaches only round a long wall moves to a cell on the team's side
that sees its target through a window too narrow for the robot; a place in plain reach stays."""

from __future__ import annotations

import numpy as np

from model.controllers.algorithms import Planner
from model.planning import path_lengths
from model.scenario import validate
from model.world.detours import DETOUR_RANGES, without_detours
from model.world.reachability import viewpoints
from model.world.visibility import segment_crosses_occupied
from model.world.world import viewing_range_of, world_of

# A wall across the domain at y = 6, open at its right end (x > 28), with a window 0.7 wide at x = 4.9 - 5.6:
# robots of radius 0.4 see through it and cannot pass.
WINDOWED = validate(
    {
        "agents": 1,
        "domain": [30.0, 12.0],
        "cell": 0.5,
        "range": 3.0,
        "robot_radius": 0.4,
        "safety": False,
        "obstacles": [
            [[0.0, 6.0], [4.9, 6.0], [4.9, 6.5], [0.0, 6.5]],
            [[5.6, 6.0], [28.0, 6.0], [28.0, 6.5], [5.6, 6.5]],
        ],
    }
)
TEAM = np.array([[5.25, 3.25]])
BEHIND_THE_WINDOW = np.array([[5.25, 7.25]])  # the centre of an uncovered cell just past the window
IN_PLAIN_REACH = np.array([[12.25, 3.75]])


def places_and_lengths(targets: np.ndarray) -> tuple:
    world = world_of(WINDOWED)
    places = viewpoints(
        world.wall_grid, world.grain, world.reachable, targets, viewing_range_of(WINDOWED), WINDOWED.cell
    )
    return world, places, path_lengths(world, TEAM, places)


def test_a_place_behind_a_window_moves_to_a_seer_on_the_team_s_side():
    world, places, lengths = places_and_lengths(BEHIND_THE_WINDOW)
    assert places.tolist() == BEHIND_THE_WINDOW.tolist()  # its own cell is reachable: round the wall's end
    assert lengths[0, 0] > 40.0
    moved_places, moved = without_detours(world, BEHIND_THE_WINDOW, places, TEAM, lengths)
    assert moved.tolist() == [True] and places.tolist() == BEHIND_THE_WINDOW.tolist()  # the input is kept
    x, y = moved_places[0]
    assert y < 6.0  # on the team's side of the wall
    assert np.hypot(x - 5.25, y - 7.25) < WINDOWED.range
    assert not segment_crosses_occupied(world.wall_grid, x, y, 5.25, 7.25, world.grain)  # it sees the target
    assert path_lengths(world, TEAM, moved_places)[0, 0] < lengths[0, 0] - DETOUR_RANGES * WINDOWED.range


def test_a_place_in_plain_reach_stays_where_it_is():
    world, places, lengths = places_and_lengths(IN_PLAIN_REACH)
    moved_places, moved = without_detours(world, IN_PLAIN_REACH, places, TEAM, lengths)
    assert moved.tolist() == [False] and moved_places.tolist() == places.tolist()


def test_the_planner_sends_the_robot_to_the_window_not_round_the_wall():
    lack = np.zeros((24, 60))
    lack[14, 10] = 1.0  # the one cell left: (5.25, 7.25)
    objective = Planner(WINDOWED).plan(lack, TEAM)
    assert objective[0, 1] < 6.0 and abs(objective[0, 0] - 5.25) < WINDOWED.range
