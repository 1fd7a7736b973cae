"""Numbers beyond float range in any file give one line naming the file and the key.

JSON and YAML read ``10**400`` as an exact integer and ``1e400`` as infinity; neither is
any setting or value we write, and each used to end as an "internal error" far from the
file (OverflowError while converting).
"""

import json
import re

import numpy as np
import pytest
from test_errors_checkpoints import neat_checkpoint, one_line_error  # noqa: F401

from evorbc_ros.config import ConfigError, config_dir, load_yaml_mapping
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.repertoire import Repertoire, RepertoireError
from evorbc_ros.sensors import SensorLayout
from offline_evolution.arbitrator.evolve import evolve
from offline_evolution.arbitrator.neat_config import load_neat_config
from offline_evolution.checkpoint import CheckpointError, Interrupted, load_checkpoint
from offline_evolution.repertoire.map_elites import generate_repertoire
from offline_evolution.repertoire.settings import load_settings
from sim_bridge.maze import load_named_maze

HUGE = "1" + "0" * 400  # 10**400, as it would stand in a file


def json_with(data, path, literal):
    """``data`` as JSON text with the value at ``path`` replaced by the text ``literal``."""
    d = json.loads(json.dumps(data))
    target = d
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = "@@@"
    return json.dumps(d).replace('"@@@"', literal)


ARB = json.loads(default_arbitrator().read_text())
REP = json.loads(default_repertoire().read_text())


@pytest.mark.parametrize("literal", [HUGE, "-" + HUGE, "1e400", "-2.5E+309"])
def test_an_arbitrator_weight_beyond_float_range(tmp_path, capsys, literal):
    path = tmp_path / "a.json"
    path.write_text(json_with(ARB, ["network", "connections", 3, "weight"], literal))
    err = one_line_error(capsys, "replay", "--arbitrator", path)
    assert err.startswith(f"evorbc-evolve: error: {path}: network.connections[3].weight: ")
    assert "is beyond float range" in err


@pytest.mark.parametrize(
    "key", [["archive", "high", 1], ["eval_time"], ["primitives", "behaviour", 7, 0], ["seed"]]
)
def test_a_repertoire_number_beyond_float_range(tmp_path, capsys, key):
    path = tmp_path / "r.json"
    path.write_text(json_with(REP, key, HUGE))
    where = ".".join(str(k) for k in key).replace(".1", "[1]").replace(".7.0", "[7][0]")
    with pytest.raises(RepertoireError, match=re.escape(f"{path}: {where}: '1000")):
        Repertoire.load(path)
    err = one_line_error(capsys, "export-csv", path, "--out", tmp_path / "r.csv")
    assert "is beyond float range" in err


def test_settings_files_with_an_integer_beyond_float_range(tmp_path, capsys):
    task = tmp_path / "task.yaml"
    task.write_text(f"mazes: [obstacle]\nepisode_time: {HUGE}\n")
    with pytest.raises(ConfigError, match=re.escape(f"{task}: episode_time is beyond float")):
        load_yaml_mapping(task)
    maze = tmp_path / "maze.yaml"
    text = (config_dir() / "mazes" / "zigzag.yaml").read_text()
    maze.write_text(text.replace("[5.495, 0.695, 5.495, -0.695]", f"[5.495, 0.695, {HUGE}, 0]"))
    with pytest.raises(ConfigError, match=re.escape(f"{maze}: walls[1][2] is beyond float")):
        load_named_maze(str(maze))
    layout = tmp_path / "layout.yaml"
    text = (config_dir() / "sensors" / "4ws.yaml").read_text()
    layout.write_text(text.replace("angles_deg: [0, 60", f"angles_deg: [{HUGE}, 60"))
    with pytest.raises(ConfigError, match=re.escape("rangefinders.angles_deg[0] is beyond")):
        SensorLayout.load(layout)
    config = tmp_path / "rep.yaml"
    config.write_text(f"robot: 4ws-5\nseed: {HUGE}\n")
    err = one_line_error(capsys, "repertoire", "--config", config, "--out", tmp_path / "r.json")
    assert err == f"evorbc-evolve: error: {config}: seed is beyond float range (at most " + (
        "about 1.8e308): no setting can hold it"
    )


def test_an_integer_setting_beyond_int64_is_refused(tmp_path, capsys):
    config = tmp_path / "rep.yaml"
    shipped = (config_dir() / "repertoire" / "4ws.yaml").read_text()
    seed = next(line for line in shipped.splitlines() if line.startswith("seed:"))
    config.write_text(shipped.replace(seed, "seed: 100000000000000000000000"))
    err = one_line_error(capsys, "repertoire", "--config", config, "--out", tmp_path / "r.json")
    assert "seed must be at most 9,223,372,036,854,775,807 in size" in err


def test_a_neat_file_with_a_number_beyond_float_range(tmp_path):
    text = (config_dir() / "neat" / "4ws.ini").read_text()
    path = tmp_path / "n.ini"
    path.write_text(text.replace("weight_mutate_power     = 0.5", f"weight_mutate_power = {HUGE}"))
    with pytest.raises(ConfigError) as info:
        load_neat_config(path, 10, 2)
    message = str(info.value)
    assert message.startswith(f"{path}: [EvoRBCGenome] weight_mutate_power must be a finite")
    assert len(message) < 200  # the 401 digits are shortened


# -- checkpoints ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("literal", "reason"),
    [
        (HUGE, "population.random_state[1][5]: '1000"),
        ("100000000000000000000000000000000000000000000000000", "population.random_state is not"),
    ],
)
def test_a_neat_checkpoint_rng_state_out_of_range(request, small_repertoire, literal, reason):
    s, ckpt = request.getfixturevalue("neat_checkpoint")  # test_errors_checkpoints' fixture
    data = json.loads(ckpt.read_text())
    ckpt.write_text(json_with(data, ["population", "random_state", 1, 5], literal))
    with pytest.raises(CheckpointError) as info:
        evolve(s, small_repertoire, checkpoint=ckpt)
    message = str(info.value)
    assert message.startswith(f"{ckpt}: ") and reason in message and "\n" not in message
    assert info.value.discardable and ckpt.exists()


@pytest.mark.parametrize(
    ("literal", "reason"),
    [(HUGE, "header: emitter.rng.state.state: '1000"), ("-1", "emitter.rng is not a random")],
)
def test_a_map_elites_checkpoint_rng_state_out_of_range(tmp_path, literal, reason):
    settings = load_settings(robot="4ws-5", initial_batch=20, batch_size=10, iterations=6)
    ckpt = tmp_path / "ck.npz"
    polls = []
    with pytest.raises(Interrupted):
        generate_repertoire(
            settings, checkpoint=ckpt, should_stop=lambda: polls.append(1) or len(polls) > 3
        )
    header, arrays = load_checkpoint(ckpt)
    text = json_with(header, ["emitter", "rng", "state", "state"], literal)
    np.savez(ckpt, __header__=np.array(text), **arrays)
    with pytest.raises(CheckpointError) as info:
        generate_repertoire(settings, checkpoint=ckpt)
    message = str(info.value)
    assert message.startswith(f"{ckpt}") and reason in message and "\n" not in message
    assert info.value.discardable
