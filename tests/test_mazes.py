"""Shipped mazes: the paper's five, 11.0 x 1.4 m, each solvable with margin in an episode.

Solvability is proved with the clearance-aware grid search of ``offline_evolution.mazes.paths``
(0.01 m cells, free where the clearance is >= 0.06 m), from the nominal start, from 50 seeded random
starts and from every clear point of the start region. The four designed mazes must be no harder
than ``obstacle``, the original authors' maze: no longer a shortest path and no longer
wall-following paths.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
import yaml

from evorbc_ros.config import ConfigError
from offline_evolution.mazes.paths import (
    MARGIN,
    ROBOT_RADIUS,
    backtrack,
    narrowest_gap,
    solve,
    stranded_starts,
    wall_followers,
)
from sim_bridge.maze import load_maze, load_named_maze, maze_from_dict, maze_names
from sim_bridge.maze_plot import plot_mazes

NAMES = ["baffles", "corridors", "gaps", "obstacle", "zigzag"]
REFERENCE = "obstacle"  # the original authors' maze, the reference for difficulty
DESIGNED = [name for name in NAMES if name != REFERENCE]
DESIGN_GAP = 0.28  # m, the narrowest gap of a designed maze, surface to surface
EPISODE_PATH = 16.0  # m; 120 s at 0.2 m/s is 24 m, and evolved controllers are not optimal
TOP_SPEED_PATH = 24.0  # m, the most a robot can drive in 120 s at 0.2 m/s


@functools.cache
def solved(name: str):
    maze = load_named_maze(name)
    return maze, solve(maze)


@functools.cache
def followers(name: str) -> dict[str, float]:
    return wall_followers(load_named_maze(name))


def nominal_path(name: str) -> float:
    maze, field = solved(name)
    return field.distance_from(*maze.start_pose[:2])


def test_the_five_4ws_mazes_the_hexapod_mazes_and_the_a1_maze_are_shipped():
    # hexapod-anywhere: the hexapod maze with starts anywhere, for training (its own file)
    assert maze_names() == sorted([*NAMES, "hexapod", "hexapod-anywhere", "a1"])


@pytest.mark.parametrize("name", NAMES)
def test_maze_has_the_papers_size_and_clear_starts(name):
    maze = load_named_maze(name)
    width, height = maze.size()
    assert 10.8 <= width <= 11.3 and 1.3 <= height <= 1.5
    assert maze.clearance(*maze.start_pose[:2]) >= ROBOT_RADIUS
    starts = maze.sample_starts(np.random.default_rng(0), 50, ROBOT_RADIUS)
    assert min(maze.clearance(x, y) for x, y, _ in starts) >= ROBOT_RADIUS
    assert maze.target_radius == 0.15


@pytest.mark.parametrize("name", NAMES)
def test_maze_is_solvable_from_every_start(name, record_property):
    maze, field = solved(name)
    nominal = field.distance_from(*maze.start_pose[:2])
    starts = maze.sample_starts(np.random.default_rng(0), 50, ROBOT_RADIUS)
    lengths = [field.distance_from(x, y) for x, y, _ in starts]
    print(
        f"{name}: shortest path {nominal:.2f} m from the nominal start, "
        f"{min(lengths):.2f}-{max(lengths):.2f} m from 50 random starts"
    )
    record_property("shortest_path_m", round(nominal, 3))
    assert nominal <= EPISODE_PATH
    assert max(lengths) <= EPISODE_PATH
    assert stranded_starts(maze, field) == 0


@pytest.mark.parametrize("name", NAMES)
def test_maze_has_no_narrow_gaps_or_deep_dead_ends(name):
    maze, field = solved(name)
    gap = narrowest_gap(maze)
    # 0.22 m less the grid's reading error (up to one 0.01 m cell).
    assert gap >= 0.21
    if name in DESIGNED:
        # Less the reading error of one cell and the bisection's resolution (0.001 m).
        assert gap >= DESIGN_GAP - 0.011
    # A goal-seeking robot never has to back away from the target by more than ~1 m.
    assert backtrack(field) <= 1.0


@pytest.mark.parametrize("name", NAMES)
def test_wall_followers_reach_the_target_in_an_episode(name):
    lengths = followers(name)
    assert set(lengths) == {"left", "right"}
    assert max(lengths.values()) <= TOP_SPEED_PATH


@pytest.mark.parametrize("name", DESIGNED)
def test_designed_maze_is_no_harder_than_the_reference(name):
    # A controller that follows walls at nearly full speed (~0.18 m/s, ~21.6 m per episode)
    # must get through every designed maze with either hand if it gets through `obstacle`
    # with the better one; and a planner's path must be no longer than in `obstacle`.
    reference = min(followers(REFERENCE).values())
    lengths = followers(name)
    print(
        f"{name}: wall followers L {lengths['left']:.2f} R {lengths['right']:.2f} m, "
        f"shortest path {nominal_path(name):.2f} m; {REFERENCE}: followers >= "
        f"{reference:.2f} m, shortest path {nominal_path(REFERENCE):.2f} m"
    )
    assert max(lengths.values()) <= reference
    assert nominal_path(name) <= nominal_path(REFERENCE)


def gaps_with_wall(wall):
    data = load_named_maze("gaps").to_dict()
    data["walls"].append(wall)
    return maze_from_dict(data, "gaps with an extra wall")


def test_a_wall_across_the_way_makes_the_maze_unsolvable():
    # Fills the first gap (0.30 m, y 0.30 to 0.60 at x = -4.5).
    maze = gaps_with_wall([-4.5, 0.29, -4.5, 0.61])
    field = solve(maze)
    assert field.distance_from(*maze.start_pose[:2]) == np.inf
    assert stranded_starts(maze, field) > 0
    assert not any(np.isfinite(list(wall_followers(maze).values())))


def test_a_gap_too_narrow_for_the_margin_blocks_the_way():
    # Leaves 0.11 m of the first gap: the robot (0.10 m) fits, but not with 0.01 m to spare
    # on both sides, so the margin counts.
    assert 2 * MARGIN > 0.11 > 2 * ROBOT_RADIUS
    maze = gaps_with_wall([-4.5, 0.295, -4.5, 0.49])
    assert solve(maze).distance_from(*maze.start_pose[:2]) == np.inf
    wider = gaps_with_wall([-4.5, 0.295, -4.5, 0.46])  # leaves 0.14 m
    assert solve(wider).distance_from(*maze.start_pose[:2]) < EPISODE_PATH


def test_a_pocket_counts_as_a_dead_end():
    # A 4 x 1 m box whose lower half is a 3 m pocket open towards the start only.
    data = {
        "name": "pocket",
        "walls": [
            [-2, 0.5, 2, 0.5],
            [2, 0.5, 2, -0.5],
            [2, -0.5, -2, -0.5],
            [-2, -0.5, -2, 0.5],
            [-1.5, 0, 1.5, 0],
            [1.5, 0, 1.5, -0.5],
        ],
        "start": {"pose": [-1.8, 0, 0], "region": {"x": [-1.9, -1.7], "y": [-0.4, 0.4]}},
        "target": [1.8, 0.25],
    }
    maze = maze_from_dict(data, "pocket")
    assert backtrack(solve(maze)) > 2.5


GOOD = {
    "name": "box",
    "wall_thickness": 0.01,
    "walls": [
        [-1, 0.5, 1, 0.5],
        [1, 0.5, 1, -0.5],
        [1, -0.5, -1, -0.5],
        [-1, -0.5, -1, 0.5],
        [0, 0.5, 0, -0.2],
    ],
    "start": {"pose": [-0.8, 0, 0], "region": {"x": [-0.9, -0.6], "y": [-0.4, 0.4]}},
    "target": [0.8, 0],
    "target_radius": 0.15,
}


def load_error(tmp_path, text):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        load_maze(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    return message


def changed(**changes):
    data = {**GOOD, **changes}
    return yaml.safe_dump(data)


def test_a_good_maze_file_loads(tmp_path):
    path = tmp_path / "box.yaml"
    path.write_text(changed())
    assert load_maze(path).to_dict()["walls"] == GOOD["walls"]


def test_unknown_key_is_named(tmp_path):
    assert "'colour'" in load_error(tmp_path, changed(colour="red"))


def test_wall_with_three_numbers_is_named(tmp_path):
    walls = [*GOOD["walls"][:4], [0, 0.5, 0]]
    assert "walls[4]" in load_error(tmp_path, changed(walls=walls))


def test_zero_length_wall_is_named(tmp_path):
    walls = [*GOOD["walls"][:4], [0.2, 0.1, 0.2, 0.1]]
    message = load_error(tmp_path, changed(walls=walls))
    assert "walls[4]" in message and "zero length" in message


def test_start_pose_outside_the_maze_is_named(tmp_path):
    start = {"pose": [-1.5, 0, 0], "region": GOOD["start"]["region"]}
    message = load_error(tmp_path, changed(start=start))
    assert "start.pose" in message and "outside" in message


def test_target_inside_a_wall_is_named(tmp_path):
    message = load_error(tmp_path, changed(target=[0.0, 0.2]))
    assert "target" in message and "inside a wall" in message


def test_start_pose_inside_a_wall_is_named(tmp_path):
    start = {"pose": [0.0, 0.3, 0], "region": GOOD["start"]["region"]}
    message = load_error(tmp_path, changed(start=start))
    assert "start.pose" in message and "inside a wall" in message


def test_start_region_outside_the_maze_is_named(tmp_path):
    start = {"pose": [-0.8, 0, 0], "region": {"x": [-1.5, -0.6], "y": [-0.4, 0.4]}}
    message = load_error(tmp_path, changed(start=start))
    assert "start.region must lie inside the maze" in message


def test_misspelt_nested_keys_are_named(tmp_path):
    region = {**GOOD["start"]["region"], "heading": [-90, 90]}
    message = load_error(tmp_path, changed(start={"pose": [-0.8, 0, 0], "region": region}))
    assert "start.region.heading" in message
    start = {**GOOD["start"], "orientation": 0}
    assert "start.orientation" in load_error(tmp_path, changed(start=start))


def test_bad_yaml_names_the_line(tmp_path):
    message = load_error(tmp_path, "name: box\nwalls: [[0, 0, 1, 1]\n")
    assert "invalid YAML" in message and "line" in message


def test_plot_mazes_writes_a_png(tmp_path):
    path = tmp_path / "mazes.png"
    plot_mazes([load_named_maze("obstacle"), load_named_maze("gaps")], path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["mazes.png"]  # no temp file left


def test_hexapod_anywhere_is_the_hexapod_maze_with_starts_anywhere():
    # hexapod-t90-any trains on both (config/tasks/
    # maze-hexapod-anywhere.yaml) and is measured on hexapod.yaml's starts alone.
    maze, anywhere = load_named_maze("hexapod"), load_named_maze("hexapod-anywhere")
    np.testing.assert_array_equal(anywhere.walls, maze.walls)
    assert anywhere.target == maze.target and anywhere.target_radius == maze.target_radius
    assert anywhere.start_pose == maze.start_pose
    assert anywhere.start_heading == pytest.approx((-math.pi, math.pi))
    lo_x, hi_x, lo_y, hi_y = maze.bounds()
    assert anywhere.start_x[1] - anywhere.start_x[0] > 0.9 * (hi_x - lo_x)
    assert anywhere.start_y[1] - anywhere.start_y[0] > 0.85 * (hi_y - lo_y)


@pytest.mark.parametrize("far", [1e30, -1e300, 5e6])
def test_a_wall_far_from_the_origin_is_refused_in_one_line(far):
    # Fuzzed mazes: 1e30 m made numpy refuse an array size, 5e6 m asked for 3 GiB.
    from evorbc_ros.config import config_dir

    data = yaml.safe_load((config_dir() / "mazes" / "obstacle.yaml").read_text())
    data["walls"][3][2] = far
    with pytest.raises(ConfigError, match=r"m\.yaml: walls\[3\] reaches .* within 500 m"):
        maze_from_dict(data, "m.yaml")
