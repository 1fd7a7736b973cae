"""Damage and mismatch sets (issue 42, docs/perturbations.md): a stuck, slow or slipping
4WS wheel, a lost, knee-locked or weak hexapod or A1 leg, a weak side.

Each shipped set loads; each damage changes the motion as documented; the draws are
seeded per row; the intact robot's results are untouched; bad set files are refused in
one line; evaluate reports each episode's damage.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.defaults import default_repertoire, paper_arbitrator
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.four_ws import FourWSGeometry
from offline_evolution.cli import main
from offline_evolution.maze_task.base import MazeTaskSettings
from offline_evolution.maze_task.evaluation import evaluate_suite
from offline_evolution.maze_task.perturbation import check_damage
from offline_evolution.maze_task.task import make_task
from sim_bridge.bringup import check_perturb
from sim_bridge.damage import FOUR_WS_CODES, KINDS, WHEELS
from sim_bridge.four_ws.damaged import damaged_body_motion, step_damaged
from sim_bridge.four_ws.motion import STATE_SIZE, body_motion, motion_limits, step_robot
from sim_bridge.four_ws.world import FourWSWorld
from sim_bridge.legged.damaged import leg_columns, leg_links, leg_sides
from sim_bridge.legged.evaluate import evaluate_genes
from sim_bridge.legged.perturbed import perturbed_sim
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.settings import load_robot_settings
from sim_bridge.maze import load_named_maze
from sim_bridge.perturbation import PerturbationSet, load_perturbations, perturbation_dir
from sim_bridge.quiet_pybullet import p

LIM = motion_limits(FourWSGeometry())
NO_BOXES, NO_CANDIDATES = np.empty((0, 6)), np.empty(0, dtype=np.int64)
SHIPPED = sorted(q.stem for q in perturbation_dir().glob("*.yaml"))
STRAIGHT = np.array([0.2, 0.0, 0.0, 0.0, 0.0])  # m/s, four wheels straight ahead


def drive(command, damage=None, cycles=50, key=7):
    """Pose ``(x m, y m, heading rad)`` after ``cycles`` steps from the origin, facing +x."""
    state = np.zeros((1, STATE_SIZE))
    for t in range(cycles):
        if damage is None:
            step_robot(state, 0, command, LIM, NO_BOXES, NO_CANDIDATES)
        else:
            d = np.asarray(damage, dtype=np.float64)
            step_damaged(state, 0, command, LIM, NO_BOXES, NO_CANDIDATES, d, key, t)
    return state[0, :3].copy()


# -- the sets ---------------------------------------------------------------------------


def test_the_issue_asks_for_these_sets_and_they_ship():
    wanted = {
        "4ws-stuck-steering": "stuck_steering",
        "4ws-slow-wheel": "slow_wheel",
        "4ws-slipping-wheel": "slipping_wheel",
        "4ws-slow-drive": None,  # a speed gain well outside realistic
        "hexapod-leg-lost": "leg_lost",
        "hexapod-knee-locked": "knee_locked",
        "hexapod-weak-side": "weak_side",
        "a1-weak-leg": "weak_leg",
        "a1-knee-locked": "knee_locked",
    }
    for name, kind in wanted.items():
        s = load_perturbations(name)
        assert s.name == name and s.description
        assert (s.damage.kind if s.damage else None) == kind
    _, hi = load_perturbations("4ws-slow-drive").wheel_speed_gain
    assert hi < load_perturbations("realistic").wheel_speed_gain[0]
    assert load_perturbations("a1-weak-leg").damage.level == (0.4, 0.4)  # 40 % torque


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_set_loads_and_documents_its_ranges(name):
    s = load_perturbations(name)
    text = (perturbation_dir() / f"{name}.yaml").read_text()
    assert (text.startswith("# ") and "docs/" in text.splitlines()[0]) or name == "realistic"
    if s.damage is not None:
        key = KINDS[s.damage.kind][2]
        if key:  # the level's line says its unit or meaning in a comment
            (line,) = [ln for ln in text.splitlines() if ln.strip().startswith(f"{key}:")]
            assert "#" in line
        assert json.loads(json.dumps(s.as_dict()))["damage"]["kind"] == s.damage.kind


@pytest.mark.parametrize(
    "damage, message",
    [
        ({"kind": "broken"}, "damage.kind must be one of stuck_steering"),
        ({"kind": "slow_wheel", "part": "fl"}, "damage.speed_factor is missing"),
        ({"kind": "slow_wheel", "speed_factor": [0.5, 1.5]}, "damage.speed_factor must be"),
        ({"kind": "slow_wheel", "speed_factor": [0.5]}, "damage.speed_factor must be"),
        ({"kind": "slow_wheel", "part": "left", "speed_factor": [0.5, 0.5]}, "damage.part"),
        ({"kind": "weak_side", "part": "fl", "strength": [0.5, 0.5]}, "damage.part"),
        ({"kind": "leg_lost", "strength": [0.5, 0.5]}, "unknown key 'strength'"),
        ({"kind": "knee_locked", "part": True}, "damage.part"),
        ("stuck", "damage must be a mapping"),
    ],
)
def test_bad_damage_is_refused_in_one_line_naming_file_and_key(tmp_path, damage, message):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"damage": damage}))
    with pytest.raises(ConfigError) as e:
        load_perturbations(str(path))
    assert str(e.value).startswith(f"{path}: ") and message in str(e.value)
    assert "\n" not in str(e.value)


def test_the_cli_refuses_a_bad_set_and_a_damage_the_robot_cannot_take(tmp_path, capsys):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"damage": {"kind": "slow_wheel", "speed_factor": [2, 3]}}))
    assert main(["evaluate", "--perturb", str(path), "--starts", "1"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "damage.speed_factor must be" in err
    # A legged damage on the 4WS robot, and a 4WS one on a differential drive.
    assert main(["evaluate", "--perturb", "hexapod-leg-lost", "--starts", "1"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "cannot apply damage leg_lost" in err
    burger = make_task(MazeTaskSettings(("obstacle",), 10.0, 1), "turtlebot3-burger")
    with pytest.raises(ValueError, match=r"damage stuck_steering \(it applies: no damage\)"):
        check_damage(burger, load_perturbations("4ws-stuck-steering"))
    check_damage(burger, load_perturbations("4ws-slow-drive"))  # a gain it does take
    with pytest.raises(ConfigError, match=r"^--perturb hexapod-leg-lost: damage leg_lost is for"):
        check_perturb("hexapod-leg-lost", "4ws-5")
    with pytest.raises(ConfigError, match="damage stuck_steering is for four_ws robots"):
        check_perturb("4ws-stuck-steering", "hexapod")
    path.write_text(yaml.safe_dump({"damage": {"kind": "knee_locked", "part": 5}}))
    capsys.readouterr()
    assert main(["evaluate", "--robot", "a1", "--perturb", str(path), "--starts", "1"]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "damage.part '5': this robot's parts are FL_toe" in err
    check_perturb("4ws-stuck-steering", "4ws-5")
    check_perturb("a1-knee-locked", "a1")


# -- seeded draws ------------------------------------------------------------------------


def test_damage_is_drawn_per_row_from_its_key_and_leaves_the_other_draws_alone():
    stuck = load_perturbations("4ws-stuck-steering")
    a = stuck.draw(np.random.default_rng([3, 1]), 400)
    b = stuck.draw(np.random.default_rng([3, 1]), 400)
    np.testing.assert_array_equal(a.kernel_arrays(2.0), b.kernel_arrays(2.0))
    other = stuck.draw(np.random.default_rng([4, 1]), 400)
    assert not np.array_equal(a.damage.level, other.damage.level)
    # Every wheel, both sides, the whole range (deg) and nothing outside it.
    wheels = a.damage.wheel_arrays()
    assert set(wheels[:, 1].astype(int)) == {0, 1, 2, 3} and set(a.damage.sign) == {-1, 1}
    assert 10 <= a.damage.level.min() < 11 and 24 < a.damage.level.max() <= 25
    np.testing.assert_allclose(np.abs(wheels[:, 2]), np.radians(a.damage.level))
    # A row's damage depends on its key alone: the first rows of a shorter draw agree.
    short = stuck.draw(np.random.default_rng([3, 1]), 1)
    assert short.damage.row(0) == stuck.damage.draw(short.keys).row(0)
    # The damage draws nothing from the set's generator: starts and noise stay put.
    plain = PerturbationSet(name="plain").draw(np.random.default_rng([3, 1]), 400)
    np.testing.assert_array_equal(plain.keys, a.keys)
    np.testing.assert_array_equal(plain.start_angle, a.start_angle)
    np.testing.assert_array_equal(plain.kernel_arrays(2.0)[:, :4], a.kernel_arrays(2.0)[:, :4])
    assert not plain.kernel_arrays(2.0)[:, 4:].any()  # no damage: code 0, the intact step


def test_a_fixed_part_is_the_same_in_every_episode(tmp_path):
    path = tmp_path / "rr.yaml"
    path.write_text(yaml.safe_dump({"damage": {"kind": "slow_wheel", "part": "rr",
                                               "speed_factor": [0.5, 0.5]}}))  # fmt: skip
    draw = load_perturbations(str(path)).draw(np.random.default_rng(0), 50)
    assert (draw.kernel_arrays(1.0)[:, 4:] == [FOUR_WS_CODES["slow_wheel"], 3, 0.5]).all()


# -- the 4WS body motion -----------------------------------------------------------------


def test_an_intact_wheel_in_the_damaged_model_gives_the_intact_motion():
    # The least-squares fit of four wheels that agree is the asked motion: a "slow" wheel
    # at factor 1 moves the body as the intact model does (to rounding).
    rng = np.random.default_rng(0)
    for _ in range(200):
        angles = np.full(4, rng.uniform(-0.7, 0.7))
        if rng.random() < 0.7:  # a turn about an ICR ahead/behind: Ackermann-like angles
            a = rng.uniform(-0.7, 0.7)
            angles = np.array([a, a, -a, -a]) if rng.random() < 0.5 else angles
        distance = rng.uniform(-0.02, 0.02)
        want = body_motion(*angles, distance, LIM)
        got = damaged_body_motion(angles, distance, LIM, FOUR_WS_CODES["slow_wheel"], 1, 1.0, 0.0)
        assert got[0] == want[0]
        np.testing.assert_allclose(got[1:], want[1:], atol=1e-15)
    # Kind 0 is the intact step itself, bit for bit.
    turn = np.array([0.2, 0.3, 0.3, -0.3, -0.3])
    for command in (STRAIGHT, turn):
        assert drive(command, [0, 0, 0]).tolist() == drive(command).tolist()


@pytest.mark.parametrize("wheel", range(4))
def test_a_stuck_steering_wheel_makes_the_robot_drift(wheel):
    intact = drive(STRAIGHT)
    assert intact.tolist() == [pytest.approx(0.96), 0.0, 0.0]  # 5 s at 0.2 m/s, ramp included
    left = drive(STRAIGHT, [FOUR_WS_CODES["stuck_steering"], wheel, math.radians(20)])
    right = drive(STRAIGHT, [FOUR_WS_CODES["stuck_steering"], wheel, math.radians(-20)])
    # A wheel stuck towards the left drags its end of the body left: a front wheel turns
    # the robot left, a rear one right; either way the robot leaves the straight line.
    front = wheel < 2
    assert (left[2] > 0.3) == front and (left[2] < -0.3) != front
    assert abs(left[1]) > 0.1 and abs(right[1]) > 0.1
    # The mirror image: the other side's wheel stuck the other way.
    mirror = drive(STRAIGHT, [FOUR_WS_CODES["stuck_steering"], wheel ^ 1, math.radians(-20)])
    assert mirror.tolist() == pytest.approx([left[0], -left[1], -left[2]], abs=1e-12)


def test_a_slow_wheel_turns_the_robot_towards_it_and_slows_it():
    for wheel, name in enumerate(WHEELS):
        pose = drive(STRAIGHT, [FOUR_WS_CODES["slow_wheel"], wheel, 0.5], cycles=5)
        on_left = name[1] == "l"
        assert (pose[2] > 0) == on_left  # turns towards the slow side
        assert 0 < math.hypot(*pose[:2]) < drive(STRAIGHT, cycles=5)[0]


def test_a_slipping_wheel_loses_traction_cycle_by_cycle_from_its_key():
    slip = [FOUR_WS_CODES["slipping_wheel"], 0, 0.9]
    a, b, c = (
        drive(STRAIGHT, slip, key=7),
        drive(STRAIGHT, slip, key=7),
        drive(STRAIGHT, slip, key=8),
    )
    assert a.tolist() == b.tolist() and a.tolist() != c.tolist()
    assert a[2] > 0.1  # the front left wheel pulls less: the robot turns left
    constant = drive(STRAIGHT, [FOUR_WS_CODES["slow_wheel"], 0, 1 - 0.45])
    assert abs(a[2] - constant[2]) < 0.5 * constant[2]  # about the mean traction loss


def test_the_bridge_world_moves_as_the_damaged_model():
    maze = load_named_maze("obstacle")
    intact, damaged = FourWSWorld(maze, "4ws-5"), FourWSWorld(maze, "4ws-5")
    try:
        draw = load_perturbations("4ws-slipping-wheel").draw(np.random.default_rng(2), 1)
        damaged.damage = draw.kernel_arrays(1.0)[0, 4:7].copy()
        damaged.damage_key = int(draw.keys[0])
        state = np.zeros((1, STATE_SIZE))
        state[0, :3] = maze.start_pose
        for t in range(10):  # 0.6 m: clear of the maze's walls
            intact.step(STRAIGHT)
            damaged.step(STRAIGHT)
            step_damaged(state, 0, STRAIGHT, LIM, NO_BOXES, NO_CANDIDATES, damaged.damage,
                         damaged.damage_key, t)  # fmt: skip
        assert list(damaged.pose) == state[0, :3].tolist()
        assert list(damaged.pose) != list(intact.pose)
    finally:
        intact.close()
        damaged.close()


# -- evaluate ----------------------------------------------------------------------------


def four_ws_suite(perturbation, seed=0):
    """The shipped 4ws-5 controller from 6 seeded starts in two paper mazes."""
    arb = ArbitratorFile.load(paper_arbitrator("4ws-5"))  # its 4-sector layout
    task = make_task(
        MazeTaskSettings(("obstacle", "zigzag"), 120.0, 1, "sensors/4ws.yaml"), "4ws-5"
    )
    controller = task.controller("evorbc", Repertoire.load(default_repertoire()), arb.mapping)
    return evaluate_suite(task, arb.network, controller, 6, seed, perturbation)


def test_evaluate_reports_each_episodes_damage_and_a_stuck_wheel_hurts():
    stuck = load_perturbations("4ws-stuck-steering")
    a, b = four_ws_suite(stuck), four_ws_suite(stuck)
    assert [e.as_dict() for e in a.episodes] == [e.as_dict() for e in b.episodes]
    intact = four_ws_suite(load_perturbations("none"))
    assert all("damage" not in e.as_dict() for e in intact.episodes)
    for e in a.episodes:
        assert e.damage.startswith(f"stuck_steering: {e.damaged_part} steering stuck at ")
        assert e.damage.endswith(" deg") and e.damaged_part in WHEELS
    assert sum(r["episodes"] for r in a.per_damage()) == len(a.episodes) == 12
    assert [e.start for e in a.episodes] == [e.start for e in intact.episodes]
    assert sum(e.reached for e in a.episodes) < sum(e.reached for e in intact.episodes)
    assert [e.as_dict() for e in four_ws_suite(stuck, seed=1).episodes] != [
        e.as_dict() for e in a.episodes
    ]


# -- legged robots -----------------------------------------------------------------------


def hexapod_settings():
    return load_robot_settings(config_dir() / "robots" / "hexapod.yaml")


def hexapod_walk() -> np.ndarray:
    """The shipped hexapod repertoire's primitive that walks farthest forward."""
    rep = Repertoire.load(default_repertoire("hexapod"))
    return rep.genes[[int(np.argmax(rep.behaviour[:, 0]))]]


def row(kind, part, level=0.0):
    """A world row with only ``kind`` damage on ``part`` (identity elsewhere)."""
    s = PerturbationSet(name="x")
    out = {q: lo for q, (lo, _) in s.ranges().items()}
    out["key"] = 0
    out["damage"] = {"kind": kind, "part": str(part), "part_u": 0.0, "level": level, "sign": 1}
    return out


def test_legs_knees_and_sides_are_found_from_the_urdf():
    with LeggedSim(hexapod_settings()) as sim:
        names = sim.settings.gait.joint_names
        assert [names[leg[0]] for leg in leg_columns(sim)] == [
            f"{leg}_tibia" for leg in ("lf", "lm", "lr", "rf", "rm", "rr")
        ]
        assert leg_sides(sim) == ["left"] * 3 + ["right"] * 3
        assert [len(links) for links in leg_links(sim)] == [3] * 6


@pytest.mark.parametrize(
    "kind, part, level",
    [("leg_lost", 1, 0.0), ("leg_limp", 1, 0.0), ("knee_locked", 0, 0.0),
     ("weak_side", "left", 0.2)],
)  # fmt: skip
def test_each_hexapod_damage_changes_its_walk_and_is_put_back(kind, part, level):
    genes = hexapod_walk()
    with LeggedSim(hexapod_settings()) as sim:
        c = sim.client

        def dynamics():
            return [
                (p.getDynamicsInfo(sim.robot, k, physicsClientId=c)[0],
                 p.getDynamicsInfo(sim.robot, k, physicsClientId=c)[1])
                for k in range(p.getNumJoints(sim.robot, physicsClientId=c))
            ], list(sim.torques), dict(sim.locked)  # fmt: skip

        before = dynamics()
        nominal = evaluate_genes(sim, genes, 2.0, 0.1, math.inf)
        with perturbed_sim(sim, row(kind, part, level)):
            damaged = evaluate_genes(sim, genes, 2.0, 0.1, math.inf)
            if kind == "knee_locked":
                assert list(sim.locked) == [leg_columns(sim)[0][0]]
        assert dynamics() == before
        again = evaluate_genes(sim, genes, 2.0, 0.1, math.inf)
    np.testing.assert_array_equal(again, nominal)  # bit for bit once put back
    moved = math.hypot(*(damaged[0, :2] - nominal[0, :2]))
    print(f"{kind}: nominal {nominal[0, :3]}, damaged {damaged[0, :3]}, {moved:.3f} m apart")
    assert moved > 0.01  # m over 2 s: the damage shows in the displacement


def test_a_lost_legs_links_touch_nothing_while_it_is_lost():
    with LeggedSim(hexapod_settings()) as sim:
        links = leg_links(sim)[4]
        with perturbed_sim(sim, row("leg_lost", 4)):
            sim.run(np.tile(sim.settings.gait.standing_pose(), (50, 1)))
            touching = {pt[3] for pt in p.getContactPoints(sim.robot, physicsClientId=sim.client)}
            assert not touching & set(links)


# -- the ROS graph -----------------------------------------------------------------------


def test_the_lockstep_graph_drives_a_damaged_robot_as_the_offline_episode(tmp_path):
    # The bridge draws one world from default_rng([seed, 1]) and steps the same damaged
    # model as the kernel: the shipped controller with a slipping wheel, bit for bit.
    from graph_helpers import GraphRun, assert_same_choices

    from evorbc_ros.defaults import default_arbitrator
    from offline_evolution.maze_task.task import MazeTask

    path = default_arbitrator()
    arb = ArbitratorFile.load(path)
    sensors = MazeTaskSettings.from_dict(arb.evolution["task"], str(path)).sensors
    task = MazeTask(MazeTaskSettings(("gaps",), 25.0, 1, sensors), arb.robot)
    controller = task.controller("evorbc", Repertoire.load(default_repertoire()), arb.mapping)
    starts = task.nominal_starts()
    slip = load_perturbations("4ws-slipping-wheel")
    world = slip.draw(np.random.default_rng([4, 1]), 1)
    result = task.evaluate([arb.network], controller, starts, record=True, world=world)
    intact = task.evaluate([arb.network], controller, starts, record=True)
    run = GraphRun(tmp_path, 183, "gaps", episode_time=25.0, arbitrator=path,
                   bridge={"perturb": "4ws-slipping-wheel", "seed": 4})  # fmt: skip
    got = run.finish(timeout=120)
    cycles = assert_same_choices(run.recorded_choices(), result)
    trajectory = np.array(got["trajectory"])
    np.testing.assert_array_equal(trajectory, result.pose[0, : cycles + 1])  # bit for bit
    assert not np.array_equal(result.pose[0, :cycles], intact.pose[0, :cycles])
    log = (tmp_path / "gaps-lockstep.log").read_text()
    assert "perturbation set 4ws-slipping-wheel (seed 4)" in log and "slipping_wheel: " in log


# -- training ----------------------------------------------------------------------------


def test_training_runs_in_damaged_worlds_and_refuses_a_damage_the_robot_cannot_take():
    from conftest import SMALL_TASK

    from offline_evolution.maze_task.task import MazeTask

    def task(perturb):
        training = {"generated": 2, "starts": 1, "pool": 0, "maze_seed": 5, "perturb": perturb}
        data = {**SMALL_TASK, "training": training}
        return MazeTask(MazeTaskSettings.from_dict(data, "t.yaml"), "4ws-5")

    with pytest.raises(ConfigError) as e:
        task("hexapod-leg-lost").start_training("4ws-5", 1, source="t.yaml")
    assert str(e.value) == (
        "t.yaml: training: perturb hexapod-leg-lost: 4ws-5: this robot's simulation cannot "
        "apply damage leg_lost (it applies: stuck_steering, slow_wheel, slipping_wheel)"
    )
    stuck = task("4ws-stuck-steering")
    stuck.start_training("4ws-5", 1, source="t.yaml")
    # A generation's worlds: drawn from the run's generator, the same again for the same seed.
    starts, world = stuck.generation_episodes(np.random.default_rng(9))
    again, world2 = stuck.generation_episodes(np.random.default_rng(9))
    np.testing.assert_array_equal(starts, again)
    np.testing.assert_array_equal(world.kernel_arrays(1.0), world2.kernel_arrays(1.0))
    assert (world.kernel_arrays(1.0)[:, 4] == FOUR_WS_CODES["stuck_steering"]).all()
