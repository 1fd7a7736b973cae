"""Relative paths in every settings file resolve beside the file that names them (issue 41).

Task and arbitrator files: tests/test_maze_fit.py. Here the robot files (``settings``,
``sensors``, ``model``, ``maze``) and a task's ``training.perturb`` set file: beside the
file wins; a path only the old location has (evorbc's ``config/`` for a robot file's
files, the working directory for maze and perturbation set files) still works, with one
deprecation line naming the file and the key; evorbc's own files say nothing.
"""

from pathlib import Path

import pytest

from evorbc_ros.config import config_dir
from evorbc_ros.robots.settings_robots import read_robot_file

BURGER = config_dir() / "robots" / "turtlebot3-burger.yaml"
LINE = "is not beside this file; taken from"


def deprecations(err: str) -> list[str]:
    return [line for line in err.splitlines() if LINE in line]


def test_a_robot_file_names_its_files_from_its_folder(tmp_path, capsys):
    folder = tmp_path / "robots"
    folder.mkdir()
    for name in ("sensors.yaml", "neat.ini"):
        source = {"sensors.yaml": "sensors/turtlebot3-burger.yaml", "neat.ini": "neat/4ws.ini"}
        (folder / name).write_text((config_dir() / source[name]).read_text())
    (folder / "m.yaml").write_text((config_dir() / "mazes" / "zigzag.yaml").read_text())
    text = BURGER.read_text()
    text = text.replace("neat: neat/4ws.ini", "neat: neat.ini")
    text = text.replace("sensors: sensors/turtlebot3-burger.yaml", "sensors: sensors.yaml")
    text = text.replace("maze: zigzag", "maze: m.yaml")
    (folder / "mine.yaml").write_text(text)
    robot = read_robot_file(folder / "mine.yaml")
    assert robot.settings.neat == str(folder / "neat.ini")
    assert robot.sensors == str(folder / "sensors.yaml")
    assert robot.maze == str(folder / "m.yaml")
    # The Burger's other files are only in config/: kept from there, one line each.
    err = deprecations(capsys.readouterr().err)
    assert robot.settings.repertoire == "repertoire/diff-drive.yaml"
    assert err == [
        f"evorbc: warning: {folder / 'mine.yaml'}: settings.{key}: {value} {LINE} "
        f"{config_dir()} (deprecated: relative paths in settings files are from the file's "
        "folder)"
        for key, value in (
            ("repertoire", "repertoire/diff-drive.yaml"),
            ("arbitrator", "arbitrator/turtlebot3-burger.yaml"),
            ("task", "tasks/maze-turtlebot3-burger.yaml"),
        )
    ]
    read_robot_file(folder / "mine.yaml")  # once per file and key, not per reading
    assert deprecations(capsys.readouterr().err) == []


def test_config_prefix_names_evorbc_s_own_files_from_anywhere(tmp_path, capsys):
    """``config:NAME``: evorbc's config/ wherever it is installed, without a line."""
    text = BURGER.read_text()
    for key in ("neat: ", "task: ", "sensors: "):  # the other two stay config-relative
        text = text.replace(key, f"{key}config:")
    (tmp_path / "mine.yaml").write_text(text)
    robot = read_robot_file(tmp_path / "mine.yaml")
    assert robot.settings.neat == "neat/4ws.ini" and robot.sensors.startswith("sensors/")
    assert robot.settings.task == "tasks/maze-turtlebot3-burger.yaml"
    # Only the two keys written without the prefix say they are not beside the file.
    assert len(deprecations(capsys.readouterr().err)) == 2
    (tmp_path / "bad.yaml").write_text(text.replace("config:neat/4ws.ini", "config:neat/no.ini"))
    with pytest.raises(Exception, match=f"{config_dir() / 'neat' / 'no.ini'}"):
        read_robot_file(tmp_path / "bad.yaml")


def test_evorbc_s_own_robot_files_name_config_without_a_line(capsys):
    robot = read_robot_file(BURGER)
    assert robot.settings.neat == "neat/4ws.ini" and robot.sensors.startswith("sensors/")
    assert deprecations(capsys.readouterr().err) == []


def test_a_maze_file_in_the_working_directory_still_works_with_a_line(
    tmp_path, monkeypatch, capsys
):
    folder = tmp_path / "robots"
    folder.mkdir()
    (tmp_path / "cwd-maze.yaml").write_text((config_dir() / "mazes" / "zigzag.yaml").read_text())
    text = BURGER.read_text().replace("maze: zigzag", "maze: cwd-maze.yaml")
    (folder / "cwd.yaml").write_text(text)
    monkeypatch.chdir(tmp_path)
    robot = read_robot_file(folder / "cwd.yaml")
    assert robot.maze == "cwd-maze.yaml"  # as before: from the working directory
    err = [line for line in deprecations(capsys.readouterr().err) if ": maze: " in line]
    assert (
        len(err) == 1 and f"{folder / 'cwd.yaml'}: maze: cwd-maze.yaml {LINE} {tmp_path}" in err[0]
    )


@pytest.mark.parametrize("where", ["beside", "cwd"])
def test_a_task_s_perturbation_set_file_resolves_beside_it(tmp_path, monkeypatch, capsys, where):
    from offline_evolution.maze_task.base import MazeTaskSettings

    tasks, run_dir = tmp_path / "tasks", tmp_path / "run"
    tasks.mkdir()
    run_dir.mkdir()
    realistic = (config_dir() / "perturbations" / "realistic.yaml").read_text()
    (tasks if where == "beside" else run_dir).joinpath("mine.yaml").write_text(realistic)
    task = tasks / "task.yaml"
    task.write_text(
        f"mazes: [gaps]\nsensors: {config_dir() / 'sensors' / '4ws.yaml'}\n"
        "training: {generated: 2, perturb: mine.yaml}\n"
    )
    monkeypatch.chdir(run_dir)
    settings = MazeTaskSettings.load(task)
    err = deprecations(capsys.readouterr().err)
    if where == "beside":
        assert settings.training.perturb == str(tasks / "mine.yaml") and err == []
    else:  # only the working directory has it, where it used to be taken from
        assert settings.training.perturb == "mine.yaml"
        assert len(err) == 1 and f"{task}: training.perturb: mine.yaml {LINE} {run_dir}" in err[0]
    # A set's name stays a name.
    task.write_text(task.read_text().replace("perturb: mine.yaml", "perturb: realistic"))
    assert MazeTaskSettings.load(task).training.perturb == "realistic"


def test_the_husky_fixture_names_evorbc_s_files_from_its_own_folder(capsys):
    here = Path(__file__).parent / "robots" / "husky"
    robot = read_robot_file(here / "husky.yaml")
    assert Path(robot.settings.neat) == (config_dir() / "neat" / "4ws.ini").resolve()
    assert deprecations(capsys.readouterr().err) == []
