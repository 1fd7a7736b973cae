"""Settings files: the shipped defaults are Table I; bad files give one-line errors."""

import pytest

from evorbc_ros.config import ConfigError, config_dir
from offline_evolution.repertoire.settings import default_settings_file, load_settings


def test_shipped_4ws_settings_are_table_one():
    s = load_settings(robot="4ws-5")
    assert (s.initial_batch, s.batch_size, s.iterations) == (10_000, 1000, 1000)
    assert (s.mutation_probability, s.mutation_sigma) == (0.25, 0.5)
    assert (s.bin_size, s.eval_time, s.metric) == (0.04, 2.0, "circular")
    assert s.evaluations == 1_010_000
    assert default_settings_file("2ws-2") == config_dir() / "repertoire" / "4ws.yaml"


def test_overrides_win_and_none_is_ignored():
    s = load_settings(robot="2ws-3", bin_size=0.02, seed=None)
    assert (s.robot, s.bin_size, s.seed) == ("2ws-3", 0.02, 0)


def error_for(tmp_path, text, **overrides):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        load_settings(path, **overrides)
    message = str(info.value)
    assert message.startswith(str(path)) and "\n" not in message
    return message


BASE = (
    "robot: 4ws-5\nmetric: circular\nbin_size: 0.04\neval_time: 2.0\n"
    "initial_batch: 10\nbatch_size: 10\niterations: 1\n"
)


def test_invalid_yaml_names_the_line(tmp_path):
    assert "line 2" in error_for(tmp_path, "robot: 4ws-5\n  metric: circular\n")


def test_unknown_key_suggests_the_right_one(tmp_path):
    assert "did you mean 'bin_size'" in error_for(tmp_path, BASE + "bin_sise: 0.02\n")


def with_setting(line: str) -> str:
    """BASE with ``line`` (``key: value``) in place of its key's line, if it has one."""
    key = line.split(":")[0]
    kept = [k for k in BASE.splitlines(keepends=True) if not k.startswith(f"{key}:")]
    return "".join(kept) + line + "\n"


def test_wrong_type_and_range(tmp_path):
    def error(line):
        return error_for(tmp_path, with_setting(line))

    assert "batch_size must be an integer" in error("batch_size: 1.5")
    assert "bin_size must be >= 0.0001" in error("bin_size: -1")
    assert "mutation_probability must be <= 1" in error("mutation_probability: 2")
    assert "metric must be one of" in error("metric: curvy")
    assert "seed must be an integer" in error("seed: true")


def test_missing_key_and_wrong_top_level(tmp_path):
    assert "missing setting 'iterations'" in error_for(
        tmp_path, BASE.replace("iterations: 1\n", "")
    )
    assert "expected a mapping" in error_for(tmp_path, "- 1\n- 2\n")


def test_missing_file(tmp_path):
    with pytest.raises(ConfigError, match="no such settings file"):
        load_settings(tmp_path / "nope.yaml")


@pytest.mark.parametrize(
    "path", sorted((config_dir() / "arbitrator").glob("*.yaml")), ids=lambda p: p.name
)
def test_every_shipped_arbitrator_run_file_loads_with_its_task_and_neat_files(path):
    from offline_evolution.arbitrator.neat_config import load_neat_config
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.maze_task.task import MazeTaskSettings

    run = load_run_settings(path)
    task = MazeTaskSettings.load(run.task_path())
    assert task.samples_per_maze >= 1 and task.episode_time > 0
    # 6 sensor inputs and the 2 mapping outputs: the same for every family's NEAT file
    assert load_neat_config(run.neat_path(), 6, 2).pop_size > 0


def test_a_task_whose_episode_is_not_whole_control_cycles_names_the_file_and_key(tmp_path):
    from offline_evolution.maze_task.task import MazeTaskSettings

    path = tmp_path / "task.yaml"
    path.write_text("mazes: [hexapod]\nepisode_time: 30.05\nsensors: sensors/hexapod.yaml\n")
    with pytest.raises(ConfigError) as info:
        MazeTaskSettings.load(path)
    message = str(info.value)
    assert message.startswith(f"{path}: episode_time") and "0.1 s control period" in message
    assert "\n" not in message


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("mazes: []\nsensors: sensors/4ws.yaml\n", "mazes must name at least one maze"),
        ("mazes: [nowhere]\nsensors: sensors/4ws.yaml\n", "mazes: unknown maze 'nowhere'"),
        ("mazes: [obstacle]\nsensors: sensors/nope.yaml\n", "sensors: no such file"),
    ],
)
def test_a_task_file_names_itself_when_what_it_refers_to_is_wrong(tmp_path, text, needle):
    from offline_evolution.maze_task.task import MazeTaskSettings

    path = tmp_path / "task.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        MazeTaskSettings.load(path)
    assert str(info.value).startswith(f"{path}: {needle}")


@pytest.mark.parametrize("key", ["neat", "task"])
def test_an_arbitrator_run_file_names_itself_when_a_referred_file_is_missing(tmp_path, key):
    from offline_evolution.arbitrator.settings import load_run_settings

    path = tmp_path / "run.yaml"
    values = {"generations": 1, "neat": "neat/4ws.ini", "task": "tasks/maze-4ws.yaml"}
    values[key] = "nope.yaml"
    path.write_text("".join(f"{k}: {v}\n" for k, v in values.items()))
    with pytest.raises(ConfigError) as info:
        load_run_settings(path)
    assert str(info.value).startswith(f"{path}: {key}: no such file")
