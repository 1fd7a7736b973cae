"""The hexapod's maze task: deterministic episodes, eq. 5 fitness and primitive choice."""

import math

import numpy as np
import pytest
from hexapod_helpers import tripod_repertoire
from neat_helpers import neat_config, network_spec, random_genomes

from evorbc_ros.mapping import MappingFunction, nearest_brute_force
from evorbc_ros.network import NetworkSpec, NodeSpec
from evorbc_ros.robots.hexapod import HexapodGeometry
from offline_evolution.maze_task.base import NOT_RUN
from offline_evolution.maze_task.hexapod_task import HexapodMazeTask
from offline_evolution.maze_task.replay import cycles_run
from offline_evolution.maze_task.task import MazeTaskSettings, eq5_fitness
from offline_evolution.task_protocol import EpisodeResult
from sim_bridge.maze import load_named_maze

EPISODE = 2.0  # s: 20 control cycles, enough to see the robot walk and turn


@pytest.fixture(scope="module")
def repertoire():
    return tripod_repertoire()


def task(workers):
    settings = MazeTaskSettings(("hexapod",), EPISODE, 1, "sensors/hexapod.yaml")
    return HexapodMazeTask(settings, workers=workers)


def networks(n_outputs, n=3, seed=0):
    config = neat_config(6, n_outputs, path="config/neat/hexapod.ini")
    return [network_spec(g, config) for g in random_genomes(config, n, seed=seed)]


FOOTPRINT_RADIUS = HexapodGeometry().footprint_radius  # about 0.31 m


def test_start_poses_keep_the_legs_clear_of_the_walls():
    maze = load_named_maze("hexapod")
    poses = maze.sample_starts(np.random.default_rng(0), 50, FOOTPRINT_RADIUS)
    assert np.all((poses[:, 0] >= -3.7) & (poses[:, 0] <= -3.3))
    assert np.all(np.abs(poses[:, 1]) <= 1.0 - FOOTPRINT_RADIUS)


def test_episodes_are_identical_on_one_or_two_workers(repertoire):
    nets = networks(2)
    starts = np.array([[0, -3.5, 0.0, 0.0], [0, -3.4, 0.3, 1.0]])
    results = []
    for workers in (1, 2):
        t = task(workers)
        try:
            controller = t.controller("evorbc", repertoire, "polar")
            results.append(t.evaluate(nets, controller, starts, record=True))
        finally:
            t.close()
    one, two = results
    for a, b in zip(one, two, strict=True):
        np.testing.assert_array_equal(a, b)
    assert one.pose.shape == (6, 21, 3) and one.choice.shape == (6, 20)
    np.testing.assert_allclose(one.pose[:, 0, :2], np.tile(starts[:, 1:3], (3, 1)), atol=0.02)
    # every cycle runs one of the repertoire's primitives
    assert set(np.unique(one.choice)) <= set(range(len(repertoire)))


def test_fitness_is_eq_5_of_the_recorded_distances(repertoire):
    t = task(1)
    try:
        controller = t.controller("evorbc", repertoire, "polar")
        r = t.evaluate(networks(2, n=2, seed=3), controller, t.nominal_starts(), record=True)
    finally:
        t.close()
    target = np.array(load_named_maze("hexapod").target)
    assert not r.reached.any() and not r.fell.any()  # 2 s is far too short to get there
    np.testing.assert_array_equal(r.cycles, 20)
    moved = r.pose[:, -1, :2]
    # eq. 5 distances: straight lines from the body centre to the target
    np.testing.assert_allclose(r.final_distance, np.linalg.norm(moved - target, axis=1))
    np.testing.assert_allclose(
        r.fitness, eq5_fitness(r.reached, r.cycles * 0.1, r.final_distance, r.initial_distance, 2)
    )


def test_a_standard_network_drives_all_37_parameters(repertoire):
    t = task(1)
    try:
        assert t.n_standard_outputs == 37
        r = t.evaluate(
            networks(37, n=2, seed=5), t.controller("standard"), t.nominal_starts(), record=True
        )
    finally:
        t.close()
    assert r.outputs.shape == (2, 20, 37)
    ran = ~np.isnan(r.outputs[:, :, 0])  # cycles before the end (a fall ends an episode)
    assert ran[:, 0].all()
    assert np.all((r.outputs[ran] >= 0) & (r.outputs[ran] <= 1))  # sigmoid outputs -> genes
    np.testing.assert_array_equal(r.choice[ran], -1)
    # A fall ends the episode where the robot lies; eq. 5 scores it there over all of T.
    for e in np.flatnonzero(r.fell):
        assert not ran[e, -1] and r.cycles[e] == 20 and not r.reached[e]
    assert [cycles_run(r, e) for e in range(2)] == ran.sum(axis=1).tolist()


def test_replay_times_a_fall_by_the_cycles_run_as_the_bridge_does():
    # Episodes of 20 cycles: one fell in its 7th cycle, one reached the target in 12, one
    # ran out. eq. 5 scores the fall over all 20 (cycles stays 20); its time is 0.7 s.
    choice = np.full((3, 20), NOT_RUN)
    choice[0, :7], choice[1, :12], choice[2, :] = 4, 4, 4
    r = EpisodeResult(
        reached=np.array([False, True, False]),
        cycles=np.array([20, 12, 20]),
        final_distance=np.zeros(3),
        initial_distance=np.ones(3),
        fitness=np.zeros(3),
        choice=choice,
        fell=np.array([True, False, False]),
    )
    assert [cycles_run(r, e) for e in range(3)] == [7, 12, 20]


def test_the_primitive_nearest_the_mapped_point_drives_the_robot(repertoire):
    """A network whose outputs are constant picks the same primitive every cycle, and the
    robot walks as that primitive walked when the repertoire was made."""
    # sigmoid(0) = 0.5 on both outputs: one fixed point of the behaviour space
    nodes = (NodeSpec(0, 0.0, 1.0, "sigmoid", "sum"), NodeSpec(1, 0.0, 1.0, "sigmoid", "sum"))
    net = NetworkSpec(tuple(range(-1, -7, -1)), (0, 1), nodes, ())
    t = task(1)
    try:
        controller = t.controller("evorbc", repertoire, "polar")
        r = t.evaluate([net], controller, t.nominal_starts(), record=True)
    finally:
        t.close()
    point = MappingFunction.for_behaviours("polar", repertoire.behaviour).point(0.5, 0.5)
    chosen = int(nearest_brute_force(repertoire.behaviour, np.array([point]))[0])
    np.testing.assert_array_equal(r.choice[0], chosen)
    # 20 cycles of one primitive are 2 s of it: the robot walks what the primitive walked
    # when it was evaluated (in the start frame), to within a few cm of contact noise.
    x0, y0, h0 = r.pose[0, 0]
    dx, dy = r.pose[0, -1, :2] - (x0, y0)
    local = (dx * math.cos(h0) + dy * math.sin(h0), -dx * math.sin(h0) + dy * math.cos(h0))
    np.testing.assert_allclose(local, repertoire.behaviour[chosen], atol=0.1)


def test_a_laser_layout_no_laserscan_can_hold_is_named_at_once(tmp_path):
    from evorbc_ros.config import ConfigError

    path = tmp_path / "uneven.yaml"
    path.write_text(
        "rangefinders:\n  angles_deg: [-75, -30, 0, 37.5, 75]\n  range: 2.0\n"
        "  mount_radius: 0.0\n  field_of_view_deg: 30\n  rays: 5\ngoal_bearing: true\n"
    )
    settings = MazeTaskSettings(("hexapod",), EPISODE, 1, str(path))
    with pytest.raises(ConfigError, match=f"{path}: the layout's rays are not evenly spaced"):
        HexapodMazeTask(settings, workers=2)
