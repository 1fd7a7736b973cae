"""The motion input (docs/design.md section 5): the distance moved over a window of odometry.

One formula and one window rule onboard (:class:`evorbc_ros.motion.MotionWindow`, used by
the radar node and the legged episodes) and in the compiled 4WS kernel; the lockstep graph
reproduces an offline episode whose choices depend on it bit for bit.
"""

import dataclasses

import numpy as np
import pytest
import yaml
from graph_helpers import assert_lockstep_reproduces

from evorbc_ros.arbitrator import Arbitrator, ArbitratorFile
from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.goal import GoalInputs
from evorbc_ros.motion import MotionWindow
from evorbc_ros.network import ConnectionSpec
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.sensors import MotionLayout, SensorLayout
from offline_evolution.maze_task.replay import replay
from offline_evolution.maze_task.task import MazeTask, MazeTaskSettings

SECOND = 1_000_000_000  # ns
LAYOUT = {
    "rangefinders": {"angles_deg": [0, 90], "range": 1.0},
    "goal_sectors": {"centres_deg": [0, 180], "width_deg": 180},
    "motion": {"window": 1.0, "distance": 0.1},
}


def test_a_layout_with_motion_names_it_last_and_reads_back_the_same():
    layout = SensorLayout.from_dict(LAYOUT)
    assert layout.n_inputs == 5 and layout.input_names()[-1] == "motion"
    assert layout.motion == MotionLayout(1.0, 0.1)
    again = SensorLayout.from_dict(layout.to_dict())
    assert again == layout and again.fingerprint() == layout.fingerprint()
    # Without the key the layout, and so its fingerprint, is what it was before motion.
    without = {k: v for k, v in LAYOUT.items() if k != "motion"}
    assert "motion" not in SensorLayout.from_dict(without).to_dict()
    assert SensorLayout.from_dict(without).fingerprint() != layout.fingerprint()
    assert GoalInputs(SensorLayout.from_dict({"motion": LAYOUT["motion"]})).names == ["motion"]


@pytest.mark.parametrize(
    ("motion", "message"),
    [
        ({"window": 0, "distance": 0.1}, "layout.yaml: motion.window must be a number > 0"),
        ({"window": 1.0}, "layout.yaml: motion.distance must be a number > 0 and <= 50, got None"),
        ({"window": 1.0, "distance": 0.1, "speed": 2}, "unknown key motion.speed"),
        ([1.0, 0.1], "layout.yaml: motion must be a mapping"),
    ],
)
def test_a_bad_motion_entry_is_one_line_naming_the_key(motion, message):
    with pytest.raises(ConfigError, match=message.replace(".", r"\.")):
        SensorLayout.from_dict({**LAYOUT, "motion": motion}, "layout.yaml")


@pytest.mark.parametrize("window", [0.25, 0.3000000006])
def test_a_task_refuses_a_window_of_no_whole_control_cycles(tmp_path, window):
    # 0.3000000006 s is 1 ns more than 3 cycles: onboard stamps (ns) would compare with
    # another pose than the kernel, so it is refused too.
    path = tmp_path / "odd.yaml"
    path.write_text(yaml.safe_dump({**LAYOUT, "motion": {"window": window, "distance": 0.1}}))
    with pytest.raises(ConfigError) as e:
        MazeTask(MazeTaskSettings(("gaps",), 10.0, 1, str(path)), "4ws-5")
    assert str(e.value) == (
        f"sensors: {path}: motion.window must be a whole number of 0.1 s control cycles, "
        f"got {window!r} s"
    )


def test_a_layout_differing_only_in_its_motion_settings_is_named_by_them():
    from evorbc_ros.arbitrator import ArbitratorError

    arb = motion_arbitrator(0.0)
    other = dataclasses.replace(arb.sensors, motion=MotionLayout(window=2.0, distance=0.1))
    with pytest.raises(ArbitratorError) as e:
        arb.check_sensors(other, "mine.yaml")
    assert str(e.value) == (
        "sensor layout mine.yaml differs from the arbitrator's (motion.window is 1.0 in the "
        "arbitrator but 2.0 now)"
    )
    with pytest.raises(ValueError, match="needs the pose's stamp"):
        GoalInputs(arb.sensors).readings(0.0, 0.0, 0.0, 1.0, 1.0)


def test_the_window_compares_with_the_pose_a_window_ago_or_the_first():
    window = MotionWindow(MotionLayout(window=1.0, distance=0.5))
    # 0.1 m/s along x, stamped every 0.1 s: before a window has passed, the distance from
    # the first pose; then always the last 1 s, 0.1 m, read as 0.2.
    got = [window.reading(k * SECOND // 10, 0.01 * k, 0.0) for k in range(15)]
    np.testing.assert_allclose(got[:11], [0.02 * k for k in range(11)], atol=1e-12)
    np.testing.assert_allclose(got[11:], 0.2, atol=1e-12)
    # Stopped: the reading falls to 0 over one window, and stays there.
    stopped = [window.reading((15 + k) * SECOND // 10, 0.14, 0.0) for k in range(12)]
    assert stopped[0] == pytest.approx(0.18) and stopped[9] == pytest.approx(0.0)
    assert stopped[10:] == [0.0, 0.0]
    # Far beyond the distance: clipped to 1. A stamp going back (a reset odometry) or
    # reset() starts again from the pose given.
    assert window.reading(3 * SECOND, 5.0, 0.0) == 1.0
    assert window.reading(0, 7.0, 7.0) == 0.0
    window.reset()
    assert window.reading(SECOND, 1.0, 1.0) == 0.0 and len(window.poses) == 1
    # Stamps that never advance: each pose replaces the last, so nothing piles up.
    for k in range(50):
        window.reading(SECOND, 1.0 + k, 1.0)
    assert len(window.poses) == 1 and window.repeated


def test_irregular_odometry_compares_with_the_newest_pose_at_least_a_window_old():
    window = MotionWindow(MotionLayout(window=1.0, distance=1.0))
    for stamp, x in ((0, 0.0), (400, 0.3), (900, 0.5), (1300, 0.7)):  # ms
        last = window.reading(stamp * 1_000_000, x, 0.0)
    # 1.3 s: the newest pose stamped at or before 0.3 s is the one at 0 s.
    assert last == pytest.approx(0.7)
    # 1.45 s: the pose at 0.4 s is now at least a window old.
    assert window.reading(1_450_000_000, 0.8, 0.0) == pytest.approx(0.5)


def motion_arbitrator(weight: float) -> ArbitratorFile:
    """The paper-protocol 4ws-5 controller with a motion input feeding m2 with ``weight``."""
    base = ArbitratorFile.load(paper_arbitrator())
    net = base.network
    net = dataclasses.replace(
        net,
        input_keys=(*net.input_keys, -(len(net.input_keys) + 1)),
        connections=(*net.connections, ConnectionSpec(-(len(net.input_keys) + 1), 1, weight, True)),
    )
    layout = dataclasses.replace(base.sensors, motion=MotionLayout(window=1.0, distance=0.1))
    return dataclasses.replace(base, network=net, sensors=layout)


@pytest.fixture(scope="module")
def motion_task(tmp_path_factory):
    """A 25-s gaps task with the 4WS layout plus motion (window 1 s, 0.1 m reads as 1)."""
    path = tmp_path_factory.mktemp("motion") / "4ws-motion.yaml"
    path.write_text(yaml.safe_dump(motion_arbitrator(0.0).sensors.to_dict()))
    return MazeTask(MazeTaskSettings(("gaps",), 25.0, 1, str(path)), "4ws-5")


def test_the_kernel_reads_motion_as_the_onboard_code_does_cycle_by_cycle(motion_task):
    """Offline choices of a controller that uses the motion input are those of the onboard
    arbitrator fed by the radar node's code (MotionWindow stamped as the bridge stamps), and
    the input matters: without its connection the episode differs."""
    from sim_bridge.four_ws.motion import STATE_SIZE, speed_through_wheels, step_robot
    from sim_bridge.sensors import read_sensors

    task = motion_task
    rep = Repertoire.load(default_repertoire())
    arb = motion_arbitrator(-2.0)
    starts = np.concatenate([task.nominal_starts(), task.sample_starts(np.random.default_rng(2))])
    _, result = replay(arb, task, starts, rep)
    _, without = replay(motion_arbitrator(0.0), task, starts, rep)
    assert not np.array_equal(result.choice, without.choice)
    controller = task.controller("evorbc", rep, "polar")
    onboard = Arbitrator(arb, rep)
    maze = task.mazes[0]
    every = np.arange(len(maze.boxes), dtype=np.int64)
    for e, row in enumerate(starts):
        goal = GoalInputs(arb.sensors)
        state = np.zeros((1, STATE_SIZE))
        state[0, :3] = row[1:]
        inputs = np.empty(task.sensors.n_inputs)
        for t in range(int(result.cycles[e])):
            np.testing.assert_array_equal(result.pose[e, t], state[0, :3])
            x, y, h = state[0, :3]
            read_sensors(x, y, h, *maze.target, x, y, task.sensors, maze.boxes, every, inputs)
            stamp = round(t * 0.1 * 1e9)  # the bridge's odometry stamp (sim_bridge.bridge_node)
            inputs[6:] = goal.readings(x, y, h, *maze.target, stamp_ns=stamp)
            choice, _ = onboard.choose(inputs)
            assert choice == result.choice[e, t], (e, t)
            command = controller.primitive_commands[choice].copy()
            command[0] = speed_through_wheels(command[0], task.robot.speed_wheel_radius)
            step_robot(state, 0, command, task.robot.limits, maze.boxes, every)


def test_a_stuck_robot_ends_its_episode_early_only_with_the_same_outcome(motion_task):
    """The kernel stops an episode at a fixed point; with a motion input only once a whole
    window stood still (the input falls to 0 over it). Recording, which never stops early,
    gives the same outcomes."""
    from neat_helpers import neat_config, network_spec, random_genomes
    from test_maze_task import compare_early_ends, constant_network

    from offline_evolution.maze_task.task import standard_controller

    task = motion_task
    starts = np.concatenate([task.sample_starts(np.random.default_rng(s)) for s in range(12)])
    standard = neat_config(n_inputs=task.layout.n_inputs, n_outputs=5)
    straight = constant_network(10.0)  # full speed ahead, wheels straight: into a wall
    straight = dataclasses.replace(straight, input_keys=(*straight.input_keys, -11))
    # Full speed while still, reversing once it moves: it rocks against the wall instead.
    rocking = dataclasses.replace(straight, connections=(ConnectionSpec(-11, 0, -30.0, True),))
    rep = Repertoire.load(default_repertoire())
    cases = [
        (
            [network_spec(g, standard) for g in random_genomes(standard, 30, seed=5)]
            + [straight, rocking],
            standard_controller(task.robot),
        ),
        (
            [motion_arbitrator(w).network for w in (0.0, -2.0, 3.0)],
            task.controller("evorbc", rep, "polar"),
        ),
    ]
    moving, settled = compare_early_ends(task, cases, starts, still_cycles=100)
    assert moving >= 10 and settled >= 10
    # The rocking robot never settles: motion moves it off every fixed point.
    rocked = task.evaluate([rocking], cases[0][1], starts, record=True)
    assert not np.any(np.all(rocked.pose[:, -1] == rocked.pose[:, -20], axis=1))


def test_the_lockstep_graph_reproduces_a_motion_controller_bit_for_bit(tmp_path, motion_task):
    rep_path = default_repertoire()
    rep = Repertoire.load(rep_path)
    arb = motion_arbitrator(-2.0)
    outcomes, result = replay(arb, motion_task, motion_task.nominal_starts(), rep)
    path = tmp_path / "motion.json"
    arb.save(path)
    controller = (str(path), str(rep_path), outcomes[0], result)
    assert_lockstep_reproduces(tmp_path, 179, "4ws-5", "gaps", controller, 25.0)


def test_the_lockstep_graph_reproduces_a_hexapod_using_motion_bit_for_bit(tmp_path):
    """The legged episodes read motion with the radar node's code, the pose stamped as the
    bridge stamps its odometry: a 4-s hexapod episode whose choices depend on it (without
    its connections they differ) runs the same through the lockstep graph."""
    from graph_helpers import switching_arbitrator
    from hexapod_helpers import tripod_repertoire

    from offline_evolution.maze_task.hexapod_task import HexapodMazeTask

    layout = SensorLayout.load(config_dir() / "sensors" / "hexapod.yaml")
    layout = dataclasses.replace(layout, motion=MotionLayout(window=1.0, distance=0.05))
    path = tmp_path / "hexapod-motion.yaml"
    path.write_text(yaml.safe_dump(layout.to_dict()))
    rep = tripod_repertoire()
    rep_path = tmp_path / "hexapod.repertoire.json"
    rep.save(rep_path)
    task = HexapodMazeTask(MazeTaskSettings(("hexapod",), 4.0, 1, str(path)), workers=1)
    try:
        arb, outcome, result = switching_arbitrator(task, rep, "hexapod", "config/neat/hexapod.ini")
        motion_key = arb.network.input_keys[-1]
        cut = dataclasses.replace(
            arb.network,
            connections=tuple(
                dataclasses.replace(c, weight=0.0) if c.source == motion_key else c
                for c in arb.network.connections
            ),
        )
        _, without = replay(dataclasses.replace(arb, network=cut), task, task.nominal_starts(), rep)
    finally:
        task.close()
    assert not np.array_equal(without.choice, result.choice)
    arb_path = tmp_path / "hexapod-motion.json"
    arb.save(arb_path)
    controller = (arb_path, rep_path, outcome, result)
    assert_lockstep_reproduces(tmp_path, 176, "hexapod", "hexapod", controller, 4.0)
