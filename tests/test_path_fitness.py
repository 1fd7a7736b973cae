"""Path-length fitness for training on generated mazes (``training.distance: path``).

docs/design.md section 22: a missed episode scores ``1 - p_final / p_initial`` with the
clearance-aware shortest path lengths instead of the straight-line distances of eq. 5.
"""

import math

import numpy as np
import pytest
import yaml
from conftest import SMALL_TASK

from evorbc_ros.config import ConfigError
from offline_evolution.maze_task.base import eq5_fitness
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings
from offline_evolution.mazes.generator import generate_maze, spec_for_robot
from offline_evolution.mazes.paths import distance_grid, solve
from sim_bridge.maze import load_named_maze

TRAINING = {"generated": 2, "starts": 1, "pool": 0, "maze_seed": 5, "post_mazes": 2}


def task(distance: str) -> MazeTask:
    values = {**SMALL_TASK, "training": {**TRAINING, "distance": distance}}
    t = MazeTask(MazeTaskSettings.from_dict(values, "t.yaml"), "4ws-5")
    t.start_training("4ws-5", seed=3)
    return t


def _grid(name: str):
    return _grid_of(load_named_maze(name))


def test_path_length_goes_around_walls_and_is_finite_everywhere():
    maze = load_named_maze("corridors")
    grid = _grid("corridors")
    assert np.isfinite(grid.values).all()
    tx, ty = maze.target
    assert grid.at(np.array([tx]), np.array([ty]))[0] < 0.02  # m, at the target
    # Left of the last block (x 4.0-4.5, y -0.7..0.22 in this maze): the straight line to
    # the target crosses the block, the path climbs over it.
    x, y = np.array([3.85]), np.array([-0.3])
    straight = math.hypot(x[0] - tx, y[0] - ty)
    assert grid.at(x, y)[0] > straight + 0.4  # m: up 0.5, over 0.5, down 0.5
    # Along the grid path from the nominal start the length falls, step by step.
    spec = spec_for_robot("4ws-5")
    field_ = solve(maze, spec.cell, spec.margin, spec.snap)
    path = field_.grid_path(*maze.start_pose[:2])[::20]
    along = grid.at(path[:, 0], path[:, 1])
    assert (np.diff(along) < 0).all()
    # A point pressed into a wall (closer than the free cells' margin) still has a value,
    # about that of the free space beside it.
    near = grid.at(np.array([3.955]), np.array([-0.3]))[0]
    assert abs(near - grid.at(x, y)[0]) < 0.15


def test_generated_mazes_carry_their_proofs_grid():
    made = generate_maze(spec_for_robot("4ws-5"), 5, 7, "train")
    again = _grid_of(made.maze)
    assert np.array_equal(made.grid.values, again.values)


def _grid_of(maze):
    spec = spec_for_robot("4ws-5")
    return distance_grid(solve(maze, spec.cell, spec.margin, spec.snap))


def test_path_fitness_scores_missed_episodes_by_path_length(small_repertoire):
    from test_training_mazes import _net

    by_path, by_line = task("path"), task("euclidean")

    starts, _ = by_path.generation_episodes(np.random.default_rng([3, 11]))
    again, _ = by_line.generation_episodes(np.random.default_rng([3, 11]))
    assert np.array_equal(starts, again)
    controller = by_path.controller("evorbc", small_repertoire, "polar")
    a = by_path.evaluate([_net()], controller, starts)
    b = by_line.evaluate([_net()], controller, starts)
    # Same episodes; the reported distances stay straight-line ones.
    assert np.array_equal(a.reached, b.reached) and np.array_equal(
        a.final_distance, b.final_distance
    )
    missed = ~a.reached
    assert missed.any()
    assert np.allclose(
        b.fitness,
        eq5_fitness(b.reached, b.cycles * 0.1, b.final_distance, b.initial_distance, 15.0),
    )
    # Path fitness from an independent search: the grid of each maze at the episode's
    # first and last position (recorded traces).
    rec = by_path.evaluate([_net()], controller, starts, record=True)
    assert np.array_equal(rec.fitness, a.fitness)
    for e in np.flatnonzero(missed):
        maze = by_path.mazes[int(starts[e, 0])]
        g = _grid_of(maze)
        first, last = rec.pose[e, 0, :2], rec.pose[e, rec.cycles[e], :2]
        p0 = g.at(first[:1], first[1:])[0]
        p1 = g.at(last[:1], last[1:])[0]
        assert a.fitness[e] == pytest.approx(1.0 - p1 / p0, abs=1e-6)
    assert not np.allclose(a.fitness[missed], b.fitness[missed])


def test_path_distance_is_recorded_only_when_set(tmp_path):
    line = MazeTaskSettings.from_dict({**SMALL_TASK, "training": TRAINING}, "t")
    assert "distance" not in line.as_dict()["training"]  # files before the setting match
    path = MazeTaskSettings.from_dict(
        {**SMALL_TASK, "training": {**TRAINING, "distance": "path"}}, "t"
    )
    assert path.as_dict()["training"]["distance"] == "path"
    assert MazeTaskSettings(**path.as_dict()).training.distance == "path"
    bad = tmp_path / "task.yaml"
    bad.write_text(yaml.safe_dump({**SMALL_TASK, "training": {**TRAINING, "distance": "geo"}}))
    with pytest.raises(ConfigError, match="training: distance 'geo': expected one of") as info:
        MazeTaskSettings.load(bad)
    assert str(bad) in str(info.value) and "\n" not in str(info.value)
