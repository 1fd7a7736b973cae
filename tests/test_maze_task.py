"""The maze task kernel: eq. 5 fitness, walls, and agreement with the onboard controller."""

import math

import numba
import numpy as np
import pytest
import yaml
from neat_helpers import neat_config, network_spec, random_genomes

from evorbc_ros.arbitrator import Arbitrator, ArbitratorFile
from evorbc_ros.network import NetworkSpec, NodeSpec
from offline_evolution.arbitrator.compiled import pack_networks
from offline_evolution.maze_task.task import (
    MazeTask,
    MazeTaskSettings,
    evorbc_controller,
    standard_controller,
)
from sim_bridge.four_ws.motion import STATE_SIZE, speed_through_wheels, step_robot
from sim_bridge.sensors import read_sensors

CORRIDOR = {
    "name": "corridor",
    "walls": [[-1, 0.5, 3, 0.5], [3, 0.5, 3, -0.5], [3, -0.5, -1, -0.5], [-1, -0.5, -1, 0.5]],
    "start": {"pose": [0, 0, 0], "region": {"x": [-0.5, 0.5], "y": [-0.3, 0.3]}},
    "target": [2.0, 0.0],
    "target_radius": 0.15,
}


def corridor_task(tmp_path, episode_time=120.0, **changes):
    path = tmp_path / "corridor.yaml"
    path.write_text(yaml.safe_dump({**CORRIDOR, **changes}))
    return MazeTask(MazeTaskSettings((str(path),), episode_time), "4ws-5")


def constant_network(speed_bias):
    """5 outputs, no connections: sigmoid(5 * 10) = 1.0 -> full speed; sigmoid(0) = 0.5 ->
    gene 0 -> wheels straight."""
    nodes = [NodeSpec(0, speed_bias, 1.0, "sigmoid", "sum")]
    nodes += [NodeSpec(k, 0.0, 1.0, "sigmoid", "sum") for k in range(1, 5)]
    return NetworkSpec(tuple(range(-1, -11, -1)), tuple(range(5)), tuple(nodes), ())


def test_reaching_the_target_scores_two_minus_the_time_share(tmp_path):
    task = corridor_task(tmp_path)
    result = task.run(
        pack_networks([constant_network(10.0)]),
        standard_controller(task.robot),
        [0],
        task.nominal_starts(),
    )
    # From rest: 0.004 + 0.008 + ... + 0.02 = 0.06 m in 5 cycles, then 0.02 m per cycle.
    # The centre is within 0.15 m of x = 2 once x >= 1.85: after 95 cycles (x = 1.86).
    assert result.reached[0] and result.cycles[0] == 95
    assert result.fitness[0] == pytest.approx(2.0 - 9.5 / 120.0, abs=1e-12)


def test_missing_the_target_scores_the_distance_gained(tmp_path):
    task = corridor_task(tmp_path, episode_time=5.0)
    result = task.run(
        pack_networks([constant_network(10.0)]),
        standard_controller(task.robot),
        [0],
        task.nominal_starts(),
    )
    # 50 cycles: x = 0.06 + 45 * 0.02 = 0.96 m, so 1.04 m of the initial 2 m remain.
    assert not result.reached[0] and result.cycles[0] == 50
    assert result.final_distance[0] == pytest.approx(1.04, abs=1e-12)
    assert result.fitness[0] == pytest.approx(1.0 - 1.04 / 2.0, abs=1e-12)


def test_a_wall_stops_the_robot_short_of_the_target(tmp_path):
    walls = [*CORRIDOR["walls"], [1.0, 0.5, 1.0, -0.5]]  # blocks the corridor at x = 1
    task = corridor_task(tmp_path, episode_time=20.0, walls=walls)
    result = task.run(
        pack_networks([constant_network(10.0)]),
        standard_controller(task.robot),
        [0],
        task.nominal_starts(),
        record=True,
    )
    x = result.pose[0, -1, 0]
    # The footprint (0.05 m) stops against the wall's near face (1 - 0.005 m): the last
    # 0.02 m step that still leaves 0.05 m of clearance ends at x = 0.94.
    assert x == pytest.approx(0.94, abs=1e-12)
    assert result.fitness[0] == pytest.approx(1.0 - 1.06 / 2.0, abs=1e-12)


@pytest.fixture(scope="module")
def five_maze_task():
    return MazeTask(
        MazeTaskSettings(("obstacle", "zigzag", "baffles", "corridors", "gaps"), 30.0), "4ws-5"
    )


def test_kernel_matches_the_onboard_controller_cycle_by_cycle(five_maze_task, small_repertoire):
    task = five_maze_task
    config = neat_config()
    specs = [network_spec(g, config) for g in random_genomes(config, 6, seed=9)]
    controller = evorbc_controller(small_repertoire, "polar", task.robot)
    starts = task.sample_starts(np.random.default_rng(3))
    result = task.run(pack_networks(specs), controller, np.arange(6), starts, record=True)
    s = task.sensors
    for g, spec in enumerate(specs):
        onboard = Arbitrator(
            ArbitratorFile("evorbc", "4ws-5", spec, task.layout, "polar", {"fingerprint": ""}),
            small_repertoire,
        )
        for j, row in enumerate(starts):
            e = g * len(starts) + j
            maze = int(row[0])
            boxes = task.mazes[maze].boxes
            every = np.arange(len(boxes), dtype=np.int64)
            tx, ty = task.mazes[maze].target
            state = np.zeros((1, STATE_SIZE))
            state[0, :3] = row[1:]
            inputs = np.empty(s.n_inputs)
            for t in range(int(result.cycles[e])):
                x, y, h = state[0, :3]
                np.testing.assert_array_equal(result.pose[e, t], state[0, :3])
                read_sensors(x, y, h, tx, ty, x, y, s, boxes, every, inputs)
                choice, _ = onboard.choose(inputs)
                assert choice == result.choice[e, t], (g, j, t)
                command = controller.primitive_commands[choice].copy()
                # The speed as onboard, through wheel rad/s (docs/design.md section 2).
                command[0] = speed_through_wheels(command[0], task.robot.speed_wheel_radius)
                step_robot(state, 0, command, task.robot.limits, boxes, every)


def test_results_do_not_depend_on_the_number_of_threads(five_maze_task, small_repertoire):
    task = five_maze_task
    config = neat_config()
    pack = pack_networks([network_spec(g, config) for g in random_genomes(config, 12)])
    controller = evorbc_controller(small_repertoire, "cartesian", task.robot)
    starts = task.sample_starts(np.random.default_rng(1))
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = task.run(pack, controller, np.arange(12), starts)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = task.run(pack, controller, np.arange(12), starts)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one.fitness, many.fitness)
    np.testing.assert_array_equal(one.cycles, many.cycles)


def test_starts_are_seeded_and_clear_of_walls(five_maze_task):
    a = five_maze_task.sample_starts(np.random.default_rng(7))
    b = five_maze_task.sample_starts(np.random.default_rng(7))
    np.testing.assert_array_equal(a, b)
    for k, x, y, _ in a:
        assert five_maze_task.mazes[int(k)].clearance(x, y) >= 0.05
    assert not np.array_equal(a, five_maze_task.sample_starts(np.random.default_rng(8)))
    assert math.isclose(a[:, 0].sum(), sum(range(5)))


def test_episodes_that_reach_a_fixed_point_end_with_the_full_episodes_outcome(small_repertoire):
    # A robot whose whole state stops changing (stopped, or pushing straight into a wall)
    # repeats that cycle forever; the kernel stops it early. Recorded episodes never stop
    # early, so they give the full episodes' outcome to compare with, bit for bit.
    task = MazeTask(MazeTaskSettings(("obstacle", "zigzag", "gaps")), "4ws-5")
    starts = task.sample_starts(np.random.default_rng(11))
    standard = neat_config(n_outputs=5)
    evorbc = neat_config(n_outputs=2)
    cases = [
        # random networks (most stand still) and two that stand still or hit a wall
        (
            [network_spec(g, standard) for g in random_genomes(standard, 40, seed=5)]
            + [constant_network(-10.0), constant_network(10.0)],
            standard_controller(task.robot),
        ),
        # random arbitrators: primitives keep most robots moving to the last cycle
        (
            [network_spec(g, evorbc) for g in random_genomes(evorbc, 40, seed=6)],
            evorbc_controller(small_repertoire, "polar", task.robot),
        ),
    ]
    moving, settled = compare_early_ends(task, cases, starts, still_cycles=200)
    # Both kinds of episode were there to compare.
    assert moving >= 10 and settled >= 10


def compare_early_ends(task, cases, starts, still_cycles):
    """Assert that each ``(networks, controller)`` case ends its episodes with the outcome
    of recorded (never early-ended) episodes; returns how many were still moving at the end
    and how many stood still over their last ``still_cycles`` cycles."""
    moving = settled = 0
    for networks, controller in cases:
        fast = task.evaluate(networks, controller, starts)
        full = task.evaluate(networks, controller, starts, record=True)
        for field in ("reached", "cycles", "final_distance", "initial_distance", "fitness"):
            assert np.array_equal(getattr(fast, field), getattr(full, field)), field
        last_step = np.any(full.pose[:, -1] != full.pose[:, -2], axis=1) & ~full.reached
        moving += int(last_step.sum())
        still = np.all(full.pose[:, -1] == full.pose[:, -still_cycles], axis=1)
        settled += int(np.sum(still))
    return moving, settled
