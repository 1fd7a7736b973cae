"""Files record the simulated robot they were made for; another design is refused."""

import dataclasses

import pytest
from hexapod_helpers import tripod_repertoire

from offline_evolution.checkpoint import settings_mismatch
from offline_evolution.cli import main


def test_mismatch_names_the_innermost_setting():
    saved = {"seed": 1, "simulation": {"geometry": {"tibia_length": 0.14, "foot": 0.012}}}
    now = {"seed": 1, "simulation": {"geometry": {"tibia_length": 0.10, "foot": 0.012}}}
    assert settings_mismatch(saved, now, "the repertoire") == (
        "simulation.geometry.tibia_length is 0.14 in the repertoire but 0.1 now"
    )
    assert settings_mismatch(saved, saved) is None


def test_mismatch_inside_lists_names_the_entry_and_stays_short():
    # A legged robot's oscillator set: 12 joints of 6 numbers. Refusing another robot's
    # file used to print both whole sets, a 2 KB line (issue 41).
    joints = [{"joint": f"leg{k}", "phase": 0.25 * k, "range": [0.1] * 4} for k in range(12)]
    other = [dict(j) for j in joints]
    other[3] = {**other[3], "phase": 0.5}
    saved, now = {"simulation": {"oscillators": joints}}, {"simulation": {"oscillators": other}}
    assert settings_mismatch(saved, now, "the repertoire") == (
        "simulation.oscillators[3].phase is 0.75 in the repertoire but 0.5 now"
    )
    fewer = {"simulation": {"oscillators": joints[:8]}}
    assert settings_mismatch(saved, fewer, "the repertoire") == (
        "simulation.oscillators has 12 entries in the repertoire but 8 now"
    )
    long = {"simulation": {"oscillators": "x" * 500}}
    line = settings_mismatch(saved, long, "the repertoire")
    assert line.startswith("simulation.oscillators is [{'joint': 'leg0'") and len(line) < 200


def test_arbitrator_cli_refuses_a_hexapod_repertoire_of_another_design(tmp_path, capsys):
    rep = tripod_repertoire()
    geometry = rep.algorithm["simulation"]["geometry"]
    first_design = {**geometry, "max_joint_velocity": 10.0}
    rep = dataclasses.replace(
        rep, algorithm={"simulation": {**rep.algorithm["simulation"], "geometry": first_design}}
    )
    path = tmp_path / "old.json"
    rep.save(path)
    out = tmp_path / "arb.json"
    code = main(["arbitrator", "--repertoire", str(path), "--generations", "1", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code != 0 and not out.exists()
    assert err == [
        f"evorbc-evolve: error: {path}: was evolved for a different robot "
        "(simulation.geometry.max_joint_velocity is 10.0 in the repertoire but 5.0 now)"
    ]


def test_a_repertoire_of_this_design_is_accepted():
    from offline_evolution.arbitrator.evolve import check_simulation
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.maze_task.task import MazeTaskSettings, make_task

    task = make_task(
        MazeTaskSettings.load(load_run_settings(robot="hexapod").task_path()), "hexapod", 1
    )
    try:
        check_simulation(tripod_repertoire(), task.describe(), "rep.json")  # no error
    finally:
        task.close()
    with pytest.raises(ValueError, match=r"rep\.json: was evolved for a different robot"):
        check_simulation(tripod_repertoire(), {"geometry": {}}, "rep.json")


def test_evorbc_sim_refuses_another_laser_naming_the_first_setting_that_differs(tmp_path):
    # The A1 controller with the hexapod's laser (2 m where the A1's reaches 2.5 m): the
    # refusal names that one setting, not both layouts (issue 41).
    from evorbc_ros.arbitration import Controller
    from evorbc_ros.arbitrator import ArbitratorFile
    from evorbc_ros.config import ConfigError, config_dir
    from evorbc_ros.defaults import default_arbitrator, default_repertoire
    from evorbc_ros.robots.registry import lookup
    from evorbc_ros.sensors import SensorLayout
    from sim_bridge.robots.adapters import check_design

    shipped = ArbitratorFile.load(default_arbitrator("a1"))
    hexapod_laser = SensorLayout.load(config_dir() / "sensors" / "hexapod.yaml")
    path = tmp_path / "a1-other-laser.json"
    dataclasses.replace(shipped, sensors=hexapod_laser).save(path)
    controller = Controller(str(path), str(default_repertoire("a1")))
    with pytest.raises(ConfigError) as e:
        check_design(lookup("a1"), controller)
    laser_file = lookup("a1").sensors_file()
    assert str(e.value) == (
        f"{path}: its sensor layout differs from the laser the bridge simulates for a1 "
        f"({laser_file}: rangefinders.range is 2.0 in the controller but 2.5 now)"
    )
    check_design(lookup("a1"), Controller(str(default_arbitrator("a1"))))  # its own passes


def test_the_arbitrator_names_the_first_sensor_setting_that_differs():
    from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
    from evorbc_ros.config import config_dir
    from evorbc_ros.defaults import default_arbitrator
    from evorbc_ros.sensors import SensorLayout

    arb = ArbitratorFile.load(default_arbitrator("4ws-5"))
    other = SensorLayout.load(config_dir() / "sensors" / "hexapod.yaml")
    with pytest.raises(ArbitratorError) as e:
        arb.check_sensors(other, "hexapod.yaml")
    line = str(e.value)
    assert line.startswith(
        "sensor layout hexapod.yaml differs from the arbitrator's (goal_bearing is None in "
        "the arbitrator but True now)"
    ), line
    assert len(line) < 160
