"""The gait design objective sees walls, maze-length episodes and the maze's speed
(docs/legged.md, "The gait design search").

The quick profile's A1 scored 100 % switching in free space and fell against walls in 14
of 20 maze episodes; its Laikago kept upright at 0.19 m/s where its maze needs 0.27 m/s
(docs/your-robot.md). Here: the A1's derived design falls more often switching against
its maze's walls than in free space, and scores lower for it; a design whose gaits are
slower than the maze needs loses mobility.
"""

import math

import numpy as np
import pytest

from evorbc_ros.config import load_yaml_mapping
from offline_evolution.commands.robot_from_urdf import write_robot_files
from offline_evolution.gait_design.maze_needs import (
    DEFAULT_EPISODE_TIME,
    DEFAULT_MAZE,
    maze_needs,
    robot_maze,
)
from offline_evolution.gait_design.objective import SPREAD, score, terms
from offline_evolution.gait_design.space import DesignSpace
from offline_evolution.mazes.generator import spec_for_robot
from sim_bridge.geometry import box_distances
from sim_bridge.legged.gait_measures import DesignMeasures, measure_design, reference_rows

GAITS, ACCURACY, EPISODES, EPISODE_TIME, SEED = 20, 2, 6, 10.0, 1


@pytest.fixture(scope="module")
def a1(tmp_path_factory) -> DesignSpace:
    """The A1 as the quick profile derives it from its URDF (named a1-urdf)."""
    out = tmp_path_factory.mktemp("a1")
    write_robot_files("pybullet_data:a1/a1.urdf", out, "a1-urdf", None, None, None, lambda _: 0)
    path = out / "a1-urdf-model.yaml"
    return DesignSpace.of(load_yaml_mapping(path), path)


def measured(space: DesignSpace, values: dict, walls) -> DesignMeasures:
    design = space.design(values)
    genes = np.random.default_rng([SEED, 0]).uniform(-1.0, 1.0, (GAITS, design.gait.n_parameters))
    reference = reference_rows(design, genes[:ACCURACY])
    return measure_design(
        design, genes, ACCURACY, EPISODES, EPISODE_TIME, SEED, reference, walls, 30.0
    )


def test_the_maze_sets_the_required_speed_and_the_room():
    needs = maze_needs(DesignSpace.of(*_a1_config()).settings)
    spec = spec_for_robot("a1")
    assert (needs.maze, needs.episode_time) == ("a1", 30.0)
    assert needs.path == pytest.approx(spec.path_limit, abs=1e-4)
    # The generator's allowance: the longest path within 2/3 of an episode at top speed.
    assert needs.required_speed == pytest.approx(spec.path_limit / 20.0, abs=1e-4)
    assert needs.room == pytest.approx(spec.narrow_gap[0], abs=1e-4)
    boxes = needs.room_boxes()
    # Four walls, each room/2 from the centre, closing it on every side.
    distances = np.array([box_distances(np.zeros(1), np.zeros(1), b)[0] for b in boxes])
    assert len(boxes) == 4 and np.allclose(distances, needs.room / 2)
    for heading in np.linspace(0.0, 2 * math.pi, 8, endpoint=False):
        far = 2.0 * needs.room * np.array([[math.cos(heading)], [math.sin(heading)]])
        assert any(_crosses(far, b) for b in boxes)
    # A robot no registration knows takes what robot-from-urdf declares for it.
    assert robot_maze("not-a-registered-robot") == (DEFAULT_MAZE, DEFAULT_EPISODE_TIME)


def _a1_config():
    from evorbc_ros.config import config_dir

    path = config_dir() / "robots" / "a1.yaml"
    return load_yaml_mapping(path), path


def _crosses(point: np.ndarray, box: np.ndarray) -> bool:
    """True if the segment from the origin to ``point`` passes through ``box``."""
    s = np.linspace(0.0, 1.0, 400)
    return bool(np.any(box_distances(point[0] * s, point[1] * s, box) == 0.0))


def test_a_design_that_falls_against_walls_scores_lower(a1):
    needs = maze_needs(a1.settings)
    values = a1.current()
    free = measured(a1, values, None)
    walled = measured(a1, values, needs.room_boxes())
    # The same gaits, seed and free-space episodes (every other one); in the others it
    # faces a wall of the room and chains its forward gaits against it, and falls more.
    assert walled.falls > free.falls and walled.switching < free.switching
    # The survival of a 30 s maze episode at the measured fall rate.
    assert walled.switching == pytest.approx(math.exp(-walled.falls * 30.0 / walled.exposure))
    assert walled.exposure < EPISODES * EPISODE_TIME
    rate, need = values["rate_hz"], needs.required_speed
    assert score(walled, rate, need) < score(free, rate, need)


def test_a_design_slower_than_the_maze_needs_loses_mobility(a1):
    needs = maze_needs(a1.settings)
    values = a1.current()
    narrow = {**values, "scale": {g: 0.2 for g in values["scale"]}}
    slow = measured(a1, narrow, None)
    fast = measured(a1, values, None)
    # Fifth of the ranges: upright and never falling, but too slow for the maze.
    assert slow.upright >= fast.upright and slow.falls == 0
    assert SPREAD * slow.speed < needs.required_speed
    slow_terms = terms(slow, values["rate_hz"], needs.required_speed)
    fast_terms = terms(fast, values["rate_hz"], needs.required_speed)
    assert slow_terms["mobility"] == pytest.approx(SPREAD * slow.speed / needs.required_speed)
    assert slow_terms["mobility"] < 0.5 < fast_terms["mobility"]
    # The same measures against a maze needing half the speed: mobility doubles (to 1).
    eased = terms(slow, values["rate_hz"], needs.required_speed / 2)
    assert eased["mobility"] == pytest.approx(min(1.0, 2 * slow_terms["mobility"]))


def test_falls_and_speed_enter_the_score():
    base = DesignMeasures(
        upright=1.0,
        switching=1.0,
        endpoint_error=0.04,
        reach=0.3,
        ms_per_evaluation=20.0,
        steady=30,
        speed=0.3,
        falls=0,
        exposure=60.0,
    )
    fell = DesignMeasures(**{**base.as_dict(), "switching": math.exp(-30.0 / 55.0), "falls": 1})
    slow = DesignMeasures(**{**base.as_dict(), "speed": 0.1})
    need = 0.43  # m/s, the A1's maze
    assert score(base, 50.0, need) == pytest.approx(1.0)
    assert score(fell, 50.0, need) == pytest.approx(math.exp(-30.0 / 55.0))
    assert score(slow, 50.0, need) == pytest.approx(SPREAD * 0.1 / need)
