"""model.controllers.anicov.terrain_routes: a tour over the stations goes room by room, 2-opt leaves no
reversal that shortens it, and a hop between rooms drives through the door on straight legs the disk can
make."""

from __future__ import annotations

import itertools

import numpy as np

from model.controllers.anicov.terrain_routes import hop_path, station_tour, travel_lengths
from model.controllers.anicov.terrain_stations import stations_among_walls
from model.world.geodesic import in_sight
from model.world.world import world_of
from tests.test_terrain_stations import ROOMS


def tour_length(tour: np.ndarray, lengths: np.ndarray) -> float:
    return float(sum(lengths[a, b] for a, b in itertools.pairwise(tour)))


def test_the_tour_visits_every_station_once_room_by_room():
    world = world_of(ROOMS)
    stations = stations_among_walls(world, 4.0)
    lengths = travel_lengths(world, stations)
    assert np.isfinite(lengths).all() and np.allclose(lengths, lengths.T)
    tour = station_tour(lengths)
    assert sorted(tour.tolist()) == list(range(len(stations)))
    side = stations[tour, 0] > 12.5
    crossings = int(np.count_nonzero(side[1:] != side[:-1]))
    # The serpentine's order (the grid's rows, as on the open square) crosses the wall at every row.
    serpentine = np.arange(len(stations))
    rows = int(np.count_nonzero((stations[1:, 0] > 12.5) != (stations[:-1, 0] > 12.5)))
    assert crossings <= 2 < rows  # room by room (the door is mid-wall: out and back once is shortest here)
    assert tour_length(tour, lengths) < tour_length(serpentine, lengths)


def test_two_opt_leaves_no_reversal_that_shortens_the_tour():
    rng = np.random.default_rng(7)
    points = rng.uniform(0.0, 100.0, (40, 2))
    lengths = np.linalg.norm(points[:, None] - points[None], axis=2)
    tour = station_tour(lengths)
    best = tour_length(tour, lengths)
    for i in range(len(tour) - 2):
        for j in range(i + 2, len(tour)):
            other = tour.copy()
            other[i + 1 : j + 1] = other[i + 1 : j + 1][::-1]
            assert tour_length(other, lengths) >= best - 1e-9
    assert tour[0] == 0


def test_a_hop_between_rooms_drives_through_the_door_on_legs_the_disk_can_make():
    world = world_of(ROOMS)
    ground = world.ground
    start, goal = np.array([3.5, 2.5]), np.array([20.5, 2.5])
    path = hop_path(world, start, goal)
    assert np.array_equal(path[0], start) and np.array_equal(path[-1], goal)
    for (x0, y0), (x1, y1) in itertools.pairwise(path):
        assert in_sight(ground.wall_grid, x0, y0, x1, y1, ground.grain, ground.plan_radius, ground.bounded)
    crossing = [(x, y) for x, y in path if 11.0 <= x <= 14.0]
    legs = np.linalg.norm(np.diff(path, axis=0), axis=1).sum()
    assert legs < float(world.field(*goal)[2, 3]) + 1e-9  # pulled tight: no longer than the graph's path
    assert legs > np.linalg.norm(goal - start) + 1.5  # round by the door, not through the wall
    door = np.interp(12.5, path[:, 0], path[:, 1])
    assert 6.0 < door < 10.0, (door, crossing)
