"""Mazes that fit the robot (docs/design.md section 21, docs/your-robot.md "Mazes").

A Husky-like robot (0.6 m footprint radius, 1 m/s; ``tests/robots/husky/``, declared by
its dimensions only) fits no paper maze as shipped: a paper maze is scaled up for it with
one warning line, its generated mazes are sized from its scaled maze, and an arbitrator
evolves and is evaluated in them. The shipped robots' mazes and generated mazes stay what
they were. Relative paths in task and arbitrator files resolve beside the file.
"""

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from evorbc_ros.robots import registry
from evorbc_ros.robots.settings_robots import PATH_VARIABLE
from offline_evolution.mazes.generator import generate_maze, spec_for_robot
from offline_evolution.mazes.paths import narrowest_gap, solve, stranded_starts
from sim_bridge.maze import load_named_maze
from sim_bridge.maze_fit import fit_scale

HUSKY = Path(__file__).parent / "robots" / "husky"


@pytest.fixture
def husky(monkeypatch):
    """The Husky-like robot registered from its settings file (this process only)."""
    monkeypatch.setenv(PATH_VARIABLE, str(HUSKY))
    registry.reset()
    spec_for_robot.cache_clear()
    yield registry.lookup("husky")
    registry.reset()
    spec_for_robot.cache_clear()


def test_husky_generated_mazes_are_sized_from_its_footprint_and_it_fits_them(husky, capsys):
    spec = spec_for_robot("husky")
    # gaps' narrowest gap (0.270 m) must hold 2 x 1.2 x 0.6 m: x5.342.
    assert spec.scale == 5.342
    # The spec says why, for the run to report; building it prints nothing.
    assert capsys.readouterr().err == ""
    assert spec.warning == (
        "generated mazes: maze gaps scaled x5.342 to fit robot husky: its "
        "narrowest gap on the way is 0.270 m and the robot needs 1.440 m (1.2 x its 0.600 m "
        "footprint radius each side)"
    )
    assert spec.margin == pytest.approx(0.72) and spec.narrow_gap[0] >= 1.44 - 0.02
    assert spec.width == pytest.approx(11.0 * 5.342, rel=0.01)
    assert spec.height == pytest.approx(1.38 * 5.342, rel=0.01)
    assert spec.target_radius == pytest.approx(0.15 * 5.342)
    assert spec.start_inset >= spec.margin
    # Episode time lets it cross: at most 2/3 of 1 m/s x 120 s of path.
    assert spec.path_limit <= 80.0
    rng = np.random.default_rng(0)
    for k in range(2):
        g = generate_maze(spec, 5, k)
        maze = g.maze
        assert g.narrowest_gap >= spec.narrow_gap[0] - 2 * spec.cell
        assert maze.start_misfit(husky.footprint_radius, "husky") is None
        field = solve(maze, spec.cell, spec.margin, spec.snap)
        assert stranded_starts(maze, field, husky.footprint_radius) == 0
        assert g.longest_path <= spec.path_limit
        starts = maze.sample_starts(rng, 5, husky.footprint_radius)
        assert all(maze.clearance(x, y) >= 0.6 for x, y, _ in starts)
        assert fit_scale(maze, husky.footprint_radius) == 1.0


def test_a_paper_maze_the_robot_does_not_fit_is_scaled_with_one_warning(husky, capsys):
    from offline_evolution.maze_task.base import MazeTaskSettings
    from offline_evolution.maze_task.task import make_task

    gaps = load_named_maze("gaps")
    task = make_task(MazeTaskSettings(("gaps",), 120.0), "husky")
    try:
        # The task prints nothing: the run that built it tells its reporters.
        assert capsys.readouterr().err == ""
        assert len(task.warnings) == 1 and task.warnings[0].startswith(
            "maze gaps scaled x5.342 to fit robot husky: "
        )
        assert task.settings.maze_scale == (5.342,)
        assert task.settings.as_dict()["maze_scale"] == [5.342]
        scaled = task.task_mazes[0]
        np.testing.assert_allclose(scaled.walls, gaps.walls * 5.342)
        assert scaled.wall_thickness == pytest.approx(gaps.wall_thickness * 5.342)
        assert scaled.target == pytest.approx(tuple(5.342 * v for v in gaps.target))
        assert scaled.target_radius == pytest.approx(gaps.target_radius * 5.342)
        assert scaled.start_x == pytest.approx(tuple(5.342 * v for v in gaps.start_x))
        assert scaled.start_heading == gaps.start_heading
        # Now it fits: the start clears it and the narrowest gap holds its margin.
        assert scaled.start_misfit(0.6, "husky") is None
        assert narrowest_gap(scaled, 0.05) >= 1.44 - 0.05
        assert fit_scale(scaled, 0.6) == 1.0
    finally:
        task.close()
    # The recorded scale is applied as it is, without a warning.
    again = make_task(MazeTaskSettings(("gaps",), 120.0, maze_scale=(5.342,)), "husky")
    again.close()
    assert again.warnings == [] and capsys.readouterr().err == ""


def test_the_husky_evolves_and_is_evaluated_in_generated_mazes(husky, tmp_path, capsys):
    from offline_evolution import cli

    repertoire, arbitrator = tmp_path / "r.json", tmp_path / "a.json"
    args = ["repertoire", "--robot", "husky", "--iterations", "2", "--quiet"]
    assert cli.main([*args, "--out", str(repertoire)]) == 0
    capsys.readouterr()
    code = cli.main(
        [
            "arbitrator",
            "--repertoire",
            str(repertoire),
            "--generations",
            "2",
            "--population",
            "10",
            "--out",
            str(arbitrator),
            "--plot",
            str(tmp_path / "a.png"),
        ]
    )
    err = capsys.readouterr().err
    assert code == 0, err
    # Once, through the run's reporters (the plan's fit; every task built after it reads
    # the recorded scale), in the command line's way.
    scaled = [line for line in err.splitlines() if "scaled x" in line]
    assert scaled == [
        "evorbc-evolve: warning: maze gaps scaled x5.342 to fit robot husky: its narrowest gap on "
        "the way is 0.270 m and the robot needs 1.440 m (1.2 x its 0.600 m footprint radius "
        "each side)"
    ]
    task = json.loads(arbitrator.read_text())["evolution"]["task"]
    assert task["mazes"] == ["gaps"] and task["maze_scale"] == [5.342]
    # Beside its task file; within the checkout, written from config/ as recorded tasks are.
    assert task["sensors"] == "../tests/robots/husky/sensors.yaml"
    report = tmp_path / "e.json"
    code = cli.main(
        [
            "evaluate",
            "--arbitrator",
            str(arbitrator),
            "--mazes",
            "paper",
            "--generated",
            "2",
            "--starts",
            "2",
            "--out",
            str(report),
        ]
    )
    err = capsys.readouterr().err
    assert code == 0, err
    # The suite fits gaps again (it names mazes, not the task): said once, by the run.
    assert [line for line in err.splitlines() if "warning: maze gaps" in line] == [scaled[0]]
    # Its generated mazes are sized from gaps scaled: said once too, by the run.
    sizing = [line for line in err.splitlines() if "generated mazes:" in line]
    assert sizing == [scaled[0].replace("warning: ", "warning: generated mazes: ")]
    result = json.loads(report.read_text())
    assert result["mazes"] == ["gaps", "gen21021-000", "gen21021-001"]
    assert result["maze_scale"] == [5.342, 1.0, 1.0]
    assert len(result["episodes"]) == 6


#: Mazes 0 and 1 of seed 7 for each shipped robot, recorded before sizing from the
#: footprint: a robot that fits its own maze gets the same mazes, wall for wall.
PINNED = {
    "4ws-5": "a386ae5020f9ecb83305259bb3b9b1a421b72600ea6269f0543d21c4d3bdb980",
    "4ws-3": "25442d9cf0c6dd2b439d9df713759ad9f387eaf7ade6f69982e2237c5c13be61",
    "2ws-2": "55a89b8f25eb14dec5f6575cf48bd52f05c0eb9cb4bd277d598ea4bd0a4cf3f7",
    "hexapod": "6d2d0421b9858ad731e70480f1d977e20aa65c49237a5c0750ae0dbf5bb6940f",
    "a1": "c215cf5f6e4d231566999594e94a8d6f23d245120612e1c7cb2895608535bc45",
}


@pytest.mark.parametrize("robot", sorted(PINNED))
def test_robots_that_fit_their_maze_generate_the_same_mazes(robot):
    spec = spec_for_robot(robot)
    assert spec.scale == 1.0
    made = [generate_maze(spec, 7, k).maze.to_dict() for k in range(2)]
    digest = hashlib.sha256(json.dumps(made, sort_keys=True).encode()).hexdigest()
    assert digest == PINNED[robot]


def test_every_shipped_robot_fits_its_task_mazes_unscaled():
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.maze_task.base import MazeTaskSettings

    for name in registry.names():
        robot = registry.lookup(name)
        settings = MazeTaskSettings.load(load_run_settings(None, name).task_path())
        for maze in settings.mazes:
            assert fit_scale(load_named_maze(maze), robot.footprint_radius) == 1.0, (name, maze)


def test_a_maze_walled_shut_is_scaled_for_its_start_only():
    from sim_bridge.maze import maze_from_dict

    box = [[-2, 1, 2, 1], [2, 1, 2, -1], [2, -1, -2, -1], [-2, -1, -2, 1], [0, 1, 0, -1]]
    closed = maze_from_dict(
        {
            "name": "closed",
            "walls": box,
            "start": {"pose": [-1.9, 0, 0], "region": {"x": [-1.2, -0.8], "y": [-0.2, 0.2]}},
            "target": [1, 0],
        },
        "closed",
    )
    # The start is 0.095 m from the left wall's surface: 0.2 m needs x2.106, whatever the way.
    assert fit_scale(closed, 0.2) == 2.106
    assert fit_scale(closed, 0.05) == 1.0


def test_task_paths_resolve_beside_the_file_and_the_old_location_warns(tmp_path, capsys):
    from evorbc_ros.config import config_dir
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.maze_task.base import MazeTaskSettings

    layout = (config_dir() / "sensors" / "4ws.yaml").read_text()
    (tmp_path / "mine.yaml").write_text(layout)
    (tmp_path / "sensors").mkdir()
    (tmp_path / "sensors" / "4ws.yaml").write_text(layout)
    maze = load_named_maze("gaps")
    (tmp_path / "m.yaml").write_text((config_dir() / "mazes" / "gaps.yaml").read_text())
    beside = tmp_path / "beside.yaml"
    beside.write_text("mazes: [zigzag, m.yaml]\nsensors: mine.yaml\n")
    settings = MazeTaskSettings.load(beside)
    assert settings.sensors == str(tmp_path / "mine.yaml")
    assert settings.mazes == ("zigzag", str(tmp_path / "m.yaml"))
    # sensors/4ws.yaml is beside it too: beside wins over config/.
    (tmp_path / "shadow.yaml").write_text("mazes: [gaps]\nsensors: sensors/4ws.yaml\n")
    assert MazeTaskSettings.load(tmp_path / "shadow.yaml").sensors == str(
        tmp_path / "sensors" / "4ws.yaml"
    )
    assert capsys.readouterr().err == ""
    # Only config/ has it: taken from there, with one deprecation line naming file and key.
    old = tmp_path / "sub" / "old.yaml"
    old.parent.mkdir()
    old.write_text("mazes: [gaps]\nsensors: sensors/4ws-p8m.yaml\n")
    assert MazeTaskSettings.load(old).sensors == "sensors/4ws-p8m.yaml"
    assert MazeTaskSettings.load(old).sensors == "sensors/4ws-p8m.yaml"
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"evorbc: warning: {old}: sensors: sensors/4ws-p8m.yaml is not beside this file; "
        f"taken from {config_dir()} (deprecated: relative paths in settings files are from "
        "the file's folder)"
    ]
    # The shipped files name their neighbours from config/, without a line; a copy of one
    # still works, with the line.
    shipped = MazeTaskSettings.load(config_dir() / "tasks" / "maze-4ws.yaml")
    assert shipped.sensors == "sensors/4ws.yaml"
    run = load_run_settings(config_dir() / "arbitrator" / "4ws.yaml")
    assert run.task_path() == config_dir() / "tasks" / "maze-4ws.yaml"
    assert capsys.readouterr().err == ""
    copy = tmp_path / "run.yaml"
    copy.write_text((config_dir() / "arbitrator" / "4ws.yaml").read_text())
    assert load_run_settings(copy).task_path() == config_dir() / "tasks" / "maze-4ws.yaml"
    assert capsys.readouterr().err.count("is not beside this file") == 2  # neat, task
    # A missing file is named where it was looked for.
    (tmp_path / "missing.yaml").write_text("mazes: [gaps]\nsensors: nope.yaml\n")
    from evorbc_ros.config import ConfigError

    with pytest.raises(ConfigError, match=f"sensors: no such file {tmp_path / 'nope.yaml'}"):
        MazeTaskSettings.load(tmp_path / "missing.yaml")
    assert maze.name == "gaps"
