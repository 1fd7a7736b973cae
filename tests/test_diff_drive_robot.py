"""A differential-drive robot declared in a settings file only (docs/your-robot.md).

The TurtleBot3 Burger ships as ``config/robots/turtlebot3-burger.yaml``; a user's robot is
a file in a folder on ``$EVORBC_ROBOT_PATH``. Both run on the compiled motion model; the
user's (a Burger with a short task) goes through repertoire, arbitrator, replay and the
lockstep ROS graph, which must drive it exactly as the offline replay does.
"""

import json
import math
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from ros_domains import claim_domain

from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.robots import registry
from evorbc_ros.robots.diff_drive import DiffDriveGeometry
from evorbc_ros.robots.settings_robots import PATH_VARIABLE, read_robot_file
from evorbc_ros.twist_executor import TwistExecutor
from sim_bridge.rosbag_io import BagReader, decode
from sim_bridge.sensors import read_sensors

BIN = os.path.dirname(sys.executable)
BURGER = config_dir() / "robots" / "turtlebot3-burger.yaml"


def test_the_burger_is_declared_by_its_settings_file_with_its_published_figures():
    burger = registry.lookup("turtlebot3-burger")
    g = burger.model
    assert (g.wheel_separation, g.wheel_radius, g.footprint_radius) == (0.160, 0.033, 0.105)
    assert (g.max_linear_speed, g.max_angular_speed) == (0.22, 2.84)
    assert [(p.name, p.unit, p.low, p.high) for p in burger.parameters] == [
        ("linear", "m/s", -0.22, 0.22),
        ("angular", "rad/s", -2.84, 2.84),
    ]
    assert burger.command_topics == ("cmd_vel",) and burger.source == str(BURGER)
    assert burger.commands == "evorbc_ros.nodes.twist_commands:TwistCommands"
    assert burger.footprint_radius == 0.105 and burger.max_speed == 0.22


def simulate(genes, seconds=2.0, **geometry):
    """``PrimitiveOutcome`` of the Burger (or the Burger with ``geometry`` changed)."""
    from sim_bridge.diff_drive.robot import DiffDriveRobot

    g = registry.lookup("turtlebot3-burger").model
    g = DiffDriveGeometry(**{**g.as_dict(), **geometry})
    return DiffDriveRobot("b", g).evaluate_primitives(np.array(genes, dtype=float), seconds)


def test_the_motion_model_drives_turns_and_is_bounded_by_the_wheels():
    out = simulate([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.5, 0.1]])
    # Full speed: 2.5 m/s^2 reaches 0.22 m/s within the first 0.1 s step.
    assert out.x[0] == pytest.approx(0.44, abs=1e-12) and out.y[0] == 0.0
    assert out.heading[0] == 0.0 and out.x[1] == pytest.approx(-0.44, abs=1e-12)
    # Turning on the spot: omega ramps up at 3.2 rad/s^2 to 2.84 rad/s, but the wheels'
    # 0.22 m/s rim speed caps it at 0.22 / 0.08 = 2.75 rad/s.
    ramp = [min(0.32 * (k + 1), 2.84, 0.22 / 0.08) for k in range(20)]
    assert out.heading[2] == pytest.approx(0.1 * sum(ramp), rel=1e-12)
    assert abs(out.x[2]) < 1e-12 and abs(out.y[2]) < 1e-12 and out.path[2] == 0.0
    # An arc: v = 0.11 m/s and omega = 0.284 rad/s, both reached in the first step, keep
    # the robot on the circle of radius v / omega about (0, r): 0.568 rad of it in 2 s.
    r = 0.11 / 0.284
    assert math.hypot(out.x[3], out.y[3] - r) == pytest.approx(r, rel=1e-12)
    assert out.heading[3] == pytest.approx(0.568, rel=1e-12)
    # Wheels twice as far apart: the same rim speeds turn the body half as fast.
    wide = simulate([[0.0, 1.0]], wheel_separation=0.32, footprint_radius=0.2)
    assert wide.heading[0] == pytest.approx(
        0.1 * sum(min(0.32 * (k + 1), 0.22 / 0.16) for k in range(20)), rel=1e-12
    )


def test_the_executor_sends_the_primitive_as_a_twist_and_stops_with_a_zero_twist():
    ex = TwistExecutor("turtlebot3-burger", registry.lookup("turtlebot3-burger").model, ["rf"])
    ex.on_input("rf", 0.0)
    ex.on_primitive([0.5, -1.0], 0.0)
    c = ex.command(0.05)
    assert (c.linear, c.angular, c.stopped) == (0.11, -2.84, False)
    c = ex.command(1.0)  # everything stale
    assert (c.linear, c.angular, c.stopped) == (0.0, 0.0, True) and "stale" in c.reason
    ex.on_input("rf", 1.0)
    ex.on_primitive([], 1.0)  # the arbitrator's "no primitive"
    c = ex.command(1.0)
    assert (c.linear, c.angular, c.stopped) == (0.0, 0.0, True)


def write(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text))
    return path


@pytest.fixture
def user_robots(tmp_path, monkeypatch):
    """A folder of the user's robot files on $EVORBC_ROBOT_PATH (for this process and
    every command it starts)."""
    folder = tmp_path / "robots"
    folder.mkdir()
    monkeypatch.setenv(PATH_VARIABLE, str(folder))
    registry.reset()
    yield folder
    registry.reset()


def without_separation(g):
    del g["wheel_separation"]


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (without_separation, "geometry: missing setting 'wheel_separation'"),
        (lambda g: g.update(control_period=0.05), "geometry: control_period is the arbitrator's"),
        (
            lambda g: g.update(max_linear_speed="fast"),
            "geometry: max_linear_speed must be a number",
        ),
        (lambda g: g.update(wheel_separation=0.5), "geometry: footprint_radius 0.105 m must hold"),
    ],
)
def test_a_bad_robot_file_is_one_line_naming_file_and_key(user_robots, edit, message):
    import yaml

    data = yaml.safe_load(BURGER.read_text())
    edit(data["geometry"])
    path = write(user_robots / "mine.yaml", yaml.safe_dump(data))
    with pytest.raises(ConfigError) as info:
        read_robot_file(path)
    assert str(info.value).startswith(f"{path}: {message}") and "\n" not in str(info.value)
    # The registry leaves it out, says so once, and names the problem when it is asked for.
    reported = []
    reg = registry.Registry(report=reported.append)
    assert "mine" not in reg.names() and "turtlebot3-burger" in reg.names()
    assert reported == [f"robot file {info.value}; left out"]
    with pytest.raises(registry.RobotError, match=f"^robot mine: {path}: "):
        reg.lookup("mine")


def test_files_without_a_kind_are_not_robots_and_a_missing_file_is_named(user_robots):
    write(user_robots / "notes.yaml", "just: settings\n")
    write(user_robots / "other.yaml", "kind: diff_drive\n")
    assert read_robot_file(user_robots / "notes.yaml") is None
    with pytest.raises(ConfigError, match=r"other\.yaml: geometry: missing setting"):
        read_robot_file(user_robots / "other.yaml")
    text = BURGER.read_text().replace("neat/4ws.ini", "neat/nosuch.ini")
    write(user_robots / "typo.yaml", text)
    with pytest.raises(ConfigError) as e:
        read_robot_file(user_robots / "typo.yaml")
    assert str(e.value) == (
        f"{user_robots / 'typo.yaml'}: settings.neat: no such file "
        f"{(user_robots / 'neat/nosuch.ini').resolve()} (relative paths are from this file's "
        "folder)"
    )


# -- a user's robot through the whole pipeline ------------------------------------------

USER_FILES = {
    "burger-test.yaml": None,  # the Burger's file, renamed, with the settings below
    "repertoire.yaml": """\
        robot: burger-test
        metric: circular
        bin_size: 0.04
        eval_time: 2.0
        initial_batch: 400
        batch_size: 100
        iterations: 10
        mutation_probability: 0.25
        mutation_sigma: 0.5
        seed: 0
        archive: grid
        variation: paper
        iso_sigma: 0.02
        line_sigma: 0.2
        """,
    "arbitrator.yaml": """\
        generations: 3
        mapping: polar
        neat: neat.ini
        task: task.yaml
        checkpoint_every: 10
        hall_of_fame: 5
        post_samples: 1
        """,
    "task.yaml": """\
        mazes: [gaps]
        episode_time: 15.0
        samples_per_maze: 1
        sensors: {folder}/sensors.yaml
        """,
    # The Burger's layout with rangefinders reaching 2.6 m from the body centre, past the
    # simulated scanner's default 2.0 m: the graph must still read what offline reads.
    "sensors.yaml": """\
        rangefinders:
          angles_deg: [0, 60, 120, 180, 240, 300]
          range: 2.5
          mount_radius: 0.105
          field_of_view_deg: 0.0
          rays: 1
        goal_sectors:
          centres_deg: [0, 90, 180, 270]
          width_deg: 90
        """,
}


@pytest.fixture(scope="module")
def pipeline(tmp_path_factory):
    """The user's robot folder and run folder; the environment every command gets."""
    root = tmp_path_factory.mktemp("diff")
    folder = root / "robots"
    for name, text in USER_FILES.items():
        if text is not None:
            write(folder / name, text.replace("{folder}", str(folder)))
    neat = (config_dir() / "neat" / "4ws.ini").read_text()
    (folder / "neat.ini").write_text(neat.replace("pop_size              = 150", "pop_size = 16"))
    burger = BURGER.read_text()
    for key in ("repertoire", "arbitrator", "task"):
        burger = burger.replace(f"  {key}: ", f"  {key}: {key}.yaml  # ", 1)
    burger = burger.replace("  neat: neat/4ws.ini", "  neat: neat.ini")
    # Relative paths are from the file's folder: the Burger's layout goes beside it.
    layout = "sensors/turtlebot3-burger.yaml"
    (folder / "burger-sensors.yaml").write_text((config_dir() / layout).read_text())
    burger = burger.replace(f"sensors: {layout}", "sensors: burger-sensors.yaml")
    burger = burger.replace("maze: zigzag", "maze: gaps").replace(
        "episode_time: 120.0", "episode_time: 15.0"
    )
    write(folder / "burger-test.yaml", burger)
    run = root / "run"
    run.mkdir()
    env = dict(os.environ, **{PATH_VARIABLE: str(folder)})
    return folder, run, env


def cli(pipeline, command, *args):
    _, run, env = pipeline
    out = subprocess.run(
        [os.path.join(BIN, command), *args],
        capture_output=True,
        text=True,
        cwd=run,
        env=env,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    assert "evorbc: warning" not in out.stderr
    return out


@pytest.fixture
def user_robot(pipeline, monkeypatch):
    """The user's robot folder on $EVORBC_ROBOT_PATH in this process too."""
    monkeypatch.setenv(PATH_VARIABLE, str(pipeline[0]))
    registry.reset()
    yield
    registry.reset()


def test_a_user_robot_file_gets_a_repertoire_from_its_name_only(pipeline, user_robot):
    from evorbc_ros.repertoire import Repertoire

    cli(pipeline, "evorbc-evolve", "repertoire", "--robot", "burger-test", "--out", "r.json")
    rep = Repertoire.load(pipeline[1] / "r.json")
    assert rep.robot == "burger-test" and rep.algorithm["evaluations"] == 400 + 10 * 100
    assert rep.algorithm["simulation"]["kinematics"] == "diff_drive"
    assert np.all(np.hypot(rep.behaviour[:, 0], rep.behaviour[:, 1]) <= 0.44 + 1e-9)
    assert len(rep) > 50 and rep.behaviour[:, 0].min() < -0.3  # it backs up, too


def test_a_user_robot_file_gets_an_arbitrator_and_a_replay(pipeline):
    out = cli(
        pipeline, "evorbc-evolve", "arbitrator", "--repertoire", "r.json", "--seed", "1",
        "--out", "a.json", "--quiet",
    )  # fmt: skip
    assert out.stdout.startswith("burger-test arbitrator: ") and "3 generations" in out.stdout
    out = cli(pipeline, "evorbc-evolve", "replay", "--arbitrator", "a.json", "--json")
    replayed = json.loads(out.stdout)["mazes"][0]
    assert replayed["maze"] == "gaps" and 0.0 < replayed["fitness"] < 2.0


def test_a_user_robot_file_drives_the_lockstep_graph_exactly_as_offline(pipeline, user_robot):
    from evorbc_ros.arbitrator import ArbitratorFile
    from evorbc_ros.repertoire import Repertoire
    from offline_evolution.maze_task.replay import replay
    from offline_evolution.maze_task.task import MazeTaskSettings, make_task

    run = pipeline[1]
    robot = registry.lookup("burger-test")
    rep = Repertoire.load(run / "r.json")
    arb = ArbitratorFile.load(run / "a.json")
    task = make_task(MazeTaskSettings.load(robot.settings_file("task")), "burger-test")
    outcomes, result = replay(arb, task, task.nominal_starts(), rep)
    cli(
        pipeline, "evorbc-sim", "--arbitrator", "a.json", "--repertoire", "r.json",
        "--result", "run.json", "--plot", "run.png", "--quiet",
        "--domain-id", str(claim_domain(178)), "--bag", "bag",
    )  # fmt: skip
    got = json.loads((run / "run.json").read_text())
    assert got["robot"] == "burger-test" and got["episode_time"] == 15.0
    cycles = int(result.cycles[0])
    # Bit for bit: the Twist carries the offline command exactly.
    np.testing.assert_array_equal(np.array(got["trajectory"]), result.pose[0, : cycles + 1])
    # And the rangefinders read what they read offline, every cycle, to the LaserScan's
    # float32 precision: walls past the scanner's default 2 m (the layout reaches 2.6 m)
    # too. The choices matched even when they read nothing there.
    with BagReader(run / "bag") as bag:
        readings = np.array(
            [
                decode(m.raw, "std_msgs/msg/Float64MultiArray").data
                for m in bag.messages(["/evorbc/rangefinders"])
            ]
        )[:cycles]
    maze = task.mazes[0]
    walls = np.arange(len(maze.boxes), dtype=np.int64)
    inputs = np.empty(task.sensors.n_inputs)
    offline = []
    for x, y, h in result.pose[0, :cycles]:
        read_sensors(x, y, h, *maze.target, x, y, task.sensors, maze.boxes, walls, inputs)
        offline.append(inputs[: readings.shape[1]].copy())
    offline = np.array(offline)
    assert np.sum((offline > 0) & (offline < 0.2)) >= 3  # walls 2.1-2.6 m from the centre
    np.testing.assert_allclose(readings, offline, rtol=0, atol=1e-6)
    assert got["fitness"] == outcomes[0].fitness and got["reached"] == outcomes[0].reached
    assert np.ptp(np.array(got["trajectory"])[:, 0]) > 0.1  # it went somewhere
