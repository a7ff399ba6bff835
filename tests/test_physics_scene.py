"""model.physics.scene: the walls as few boxes that cover exactly the wall squares, and a world MuJoCo loads."""

import math

import mujoco
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from model.parameters import starting_poses
from model.physics.base import base_of
from model.physics.scene import PHYSICS_SUBSTEPS, scene_xml, wall_boxes
from model.scenario import validate
from model.world.world import world_of


@settings(max_examples=200)
@given(arrays(np.bool_, st.tuples(st.integers(1, 12), st.integers(1, 12))))
def test_the_boxes_cover_every_wall_square_once_and_nothing_else(grid):
    grain = 0.5
    drawn = np.zeros(grid.shape, dtype=np.int64)
    for x0, y0, x1, y1 in wall_boxes(grid, grain):
        drawn[round(y0 / grain) : round(y1 / grain), round(x0 / grain) : round(x1 / grain)] += 1
    assert np.array_equal(drawn, grid.astype(np.int64))


def test_runs_of_rows_are_stacked_into_one_box():
    grid = np.zeros((6, 6), dtype=bool)
    grid[1:5, 2:4] = True  # one 2 x 4 block
    assert wall_boxes(grid, 1.0) == [(2.0, 1.0, 4.0, 5.0)]


def test_the_world_loads_with_one_body_and_two_wheel_servos_per_robot_and_the_walls():
    scenario = validate({
        "domain": [12.0, 8.0], "cell": 1.0, "robot_radius": 0.4, "physics": "mujoco", "agents": 3, "seed": 1,
        "obstacles": [[[6.0, 0.0], [7.0, 0.0], [7.0, 5.0], [6.0, 5.0]]],
    })  # fmt: skip
    world = world_of(scenario)
    model = mujoco.MjModel.from_xml_string(
        scene_xml(scenario.domain, world.ground, base_of(scenario), starting_poses(scenario), scenario.dt)
    )
    assert model.nu == 6 and all(model.body(f"robot{i}").id > 0 for i in range(3))
    walls = [model.geom(g).name for g in range(model.ngeom) if model.geom(g).name.startswith("wall")]
    assert len(walls) == len(wall_boxes(world.ground.wall_grid, world.ground.grain)) + (
        4 if world.ground.bounded else 0
    )
    assert math.isclose(model.opt.timestep * PHYSICS_SUBSTEPS, scenario.dt)
