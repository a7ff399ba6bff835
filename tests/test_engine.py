import numpy as np
import pytest

from anicov.engine import run_scenario
from model.paper.metrics import optimum_time, total_sensing_ability
from model.parameters import initial_poses
from model.run import TRACE_FIELDS
from model.scenario import validate
from model.world.clearance import disk_is_free
from model.world.world import world_of
from runtime.rundir import format_summary, summary_of


def test_initial_poses_are_seeded_and_inside_the_domain(paper_scenario):
    poses = initial_poses(paper_scenario.with_overrides(agents=50, seed=5))
    assert np.array_equal(poses, initial_poses(paper_scenario.with_overrides(agents=50, seed=5)))
    assert not np.array_equal(poses, initial_poses(paper_scenario.with_overrides(agents=50, seed=6)))
    assert ((poses[:, :2] >= 0) & (poses[:, :2] <= 100)).all()
    assert ((poses[:, 2] >= -np.pi) & (poses[:, 2] <= np.pi)).all()


def test_same_seed_gives_identical_runs(paper_scenario):
    scenario = paper_scenario.with_overrides(agents=3, seed=11)
    first, second = run_scenario(scenario), run_scenario(scenario)
    assert first.trace.tobytes() == second.trace.tobytes()
    assert first.errors.tobytes() == second.errors.tobytes()


def test_golden_paper_run_four_agents_seed_0(paper_scenario):
    """Golden values of `anicov run --n 4 --seed 0` (scenarios/paper.toml), recorded from this engine.

    They pin the arithmetic of eq. 1–16 and Algorithms 1–2 as a whole: a change
    to any of them moves the step count. The paper's own 4-agent run ended at
    t = 592; this one ends at 605.0.
    """
    result = run_scenario(paper_scenario.with_overrides(agents=4, seed=0))
    assert result.completed
    assert result.steps == 6050
    assert result.completion_time == pytest.approx(605.0)
    assert result.path_lengths.sum() == pytest.approx(1487.004965724296, rel=1e-12)


def test_trace_rows_and_final_state(paper_scenario):
    scenario = paper_scenario.with_overrides(agents=2, seed=1)
    result = run_scenario(scenario)
    assert result.trace.shape == (result.steps + 1, 2, len(TRACE_FIELDS))
    assert np.array_equal(result.trace[0, :, :3], initial_poses(scenario))
    assert (result.trace[-1, :, 3:5] == 0.0).all()
    assert result.errors[0] == 1.0 and result.errors[-1] == 0.0
    assert (np.diff(result.errors) <= 0.0).all()
    assert (result.final_lack == 0.0).all()
    assert (np.abs(result.trace[:-1, :, 3]) <= scenario.k_v + 1e-12).all()
    assert (np.abs(result.trace[:-1, :, 4]) <= scenario.k_omega * np.pi + 1e-12).all()


def test_max_time_stops_an_unfinished_run(paper_scenario):
    result = run_scenario(paper_scenario.with_overrides(agents=1, max_time=20.0))
    assert not result.completed
    assert result.steps == 200
    assert result.completion_time == np.inf


def test_paper_run_is_within_a_factor_of_the_optimum(paper_scenario):
    """The law must beat the zig-zag's 3.27·t* for a small team, and cannot beat the optimum."""
    scenario = paper_scenario.with_overrides(agents=4, seed=2)
    result = run_scenario(scenario, record_trace=False)
    optimum = optimum_time(1e4, 100.0, total_sensing_ability(20.0, scenario.half_angle, 50.0), 4)
    assert result.completed
    assert 1.0 < result.completion_time / optimum < 4.5


@pytest.mark.slow
def test_halving_cell_and_dt_moves_mean_completion_time_under_5_percent(paper_scenario):
    seeds = range(12)
    coarse = [run_scenario(paper_scenario.with_overrides(seed=s), record_trace=False).completion_time for s in seeds]
    fine_scenario = paper_scenario.with_overrides(cell=0.5, dt=0.05)
    fine = [run_scenario(fine_scenario.with_overrides(seed=s), record_trace=False).completion_time for s in seeds]
    assert abs(np.mean(fine) - np.mean(coarse)) / np.mean(coarse) < 0.05


# ---------------------------------------------------------------- terrain (issue 11)

CORRIDOR = [[[0.0, 0.0], [40.0, 0.0], [40.0, 4.0], [0.0, 4.0]], [[0.0, 8.0], [40.0, 8.0], [40.0, 12.0], [0.0, 12.0]]]


def test_an_empty_map_gives_the_papers_run_byte_for_byte(tmp_path, paper_scenario):
    from tests.conftest import write_map

    open_run = run_scenario(paper_scenario)
    # The equality below says something only if the paper's robots never try to leave the domain,
    # which a map forbids: they do not in this run.
    assert open_run.trace[:, :, :2].min() > 0.0 and open_run.trace[:, :, :2].max() < 100.0
    write_map(tmp_path, "empty", np.zeros((100, 100), dtype=bool))
    on_map = run_scenario(validate({**paper_scenario.to_dict(), "map": "empty.yaml", "domain": [100, 100]}, tmp_path))
    assert np.array_equal(on_map.trace, open_run.trace) and np.array_equal(on_map.errors, open_run.errors)
    assert on_map.completion_time == open_run.completion_time


def test_a_robot_in_a_corridor_never_touches_its_walls():
    scenario = validate(
        {"domain": [40.0, 12.0], "obstacles": CORRIDOR, "robot_radius": 0.5, "agents": 2, "max_time": 400.0}
    )
    world = world_of(scenario)
    result = run_scenario(scenario)
    assert result.completed
    for x, y, *_ in result.trace.reshape(-1, len(TRACE_FIELDS)):
        assert disk_is_free(world.occupied, x, y, 0.5, 1.0, False)
    assert np.abs(result.trace[:, :, 3]).sum() > 0.0


def test_objectives_behind_a_wall_are_reached_through_its_door():
    # A wall across the domain with a 4-unit door at one end: half the domain lies behind it.
    wall = [[[0.0, 19.0], [26.0, 19.0], [26.0, 21.0], [0.0, 21.0]]]
    scenario = validate(
        {"domain": [30.0, 40.0], "obstacles": wall, "robot_radius": 0.4, "agents": 1, "seed": 2, "max_time": 2000.0}
    )
    result = run_scenario(scenario)
    assert result.completed
    ys = result.trace[:, 0, 1]
    assert ys.min() < 19.0 and ys.max() > 21.0  # it went to both sides, through the door
    crossings = result.trace[np.abs(ys - 20.0) < 1.0, 0, 0]
    assert (crossings > 26.0).all()  # and only through the door


def test_an_enclosed_room_is_reported_and_the_run_still_completes():
    from tests.test_world import CLOSED_ROOM

    scenario = validate(
        {"domain": [30.0, 30.0], "obstacles": CLOSED_ROOM, "robot_radius": 0.4, "agents": 3, "max_time": 2000.0}
    )
    result = run_scenario(scenario)
    assert result.completed and result.errors[-1] == 0.0
    summary = summary_of(result)
    assert summary["terrain"]["unreachable_cells"] == 36
    assert (result.final_lack[12:18, 12:18] == 0.0).all()  # the room is out of Υ, not covered
    assert "36 free but unreachable" in format_summary(summary)


def test_a_priority_map_asks_less_where_it_is_dark_and_the_run_still_completes(tmp_path):
    import cv2

    image = np.full((30, 30), 255, dtype=np.uint8)
    image[:, :15] = 0  # the left half needs only lambda_star_min
    cv2.imwrite(str(tmp_path / "priority.png"), image)
    base = {"domain": [30.0, 30.0], "agents": 2, "seed": 1, "max_time": 3000.0}
    uniform = run_scenario(validate({**base, "lambda_star": 100.0}))
    priority = validate(
        {**base, "lambda_star": "priority.png", "lambda_star_min": 25.0, "lambda_star_max": 100.0}, tmp_path
    )
    result = run_scenario(priority)
    assert uniform.completed and result.completed and result.errors[-1] == 0.0
    assert result.completion_time < uniform.completion_time
    summary = summary_of(result)
    assert summary["optimum_time"] == pytest.approx(summary_of(uniform)["optimum_time"] * (0.5 * 0.25 + 0.5))
