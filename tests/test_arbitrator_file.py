"""Arbitrator files: round trip, one-line errors, repertoire and sensor mismatches."""

import json

import numpy as np
import pytest
from neat_helpers import neat_config, network_spec, random_genomes

from evorbc_ros.arbitrator import Arbitrator, ArbitratorError, ArbitratorFile, DirectController
from evorbc_ros.config import config_dir
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.four_ws import FourWSGeometry
from evorbc_ros.robots.registry import robot_type
from evorbc_ros.sensors import SensorLayout

LAYOUT = SensorLayout.load(config_dir() / "sensors" / "4ws.yaml")


@pytest.fixture
def arbitrator(small_repertoire):
    config = neat_config()
    spec = network_spec(random_genomes(config, 1, seed=2)[0], config)
    return ArbitratorFile(
        "evorbc",
        "4ws-5",
        spec,
        LAYOUT,
        "polar",
        {
            "fingerprint": small_repertoire.fingerprint(),
            "robot": "4ws-5",
            "count": len(small_repertoire),
            "file": "r.json",
        },
        evolution={"seed": 1},
    )


@pytest.fixture
def saved(tmp_path, arbitrator):
    path = tmp_path / "a.json"
    arbitrator.save(path)
    return path


def load_error(path):
    with pytest.raises(ArbitratorError) as info:
        ArbitratorFile.load(path)
    message = str(info.value)
    assert message.startswith(str(path)) and "\n" not in message
    return message


def rewrite(path, edit):
    data = json.loads(path.read_text())
    edit(data)
    path.write_text(json.dumps(data))


def test_round_trip(saved, arbitrator, small_repertoire):
    loaded = ArbitratorFile.load(saved)
    assert loaded.network == arbitrator.network and loaded.mapping == "polar"
    assert loaded.sensors == LAYOUT and loaded.evolution == {"seed": 1}
    data = json.loads(saved.read_text())
    assert data["inputs"][0] == "range_000" and data["inputs"][-1] == "goal_sector_270"
    x = np.linspace(0, 1, 10)
    a, b = Arbitrator(arbitrator, small_repertoire), Arbitrator(loaded, small_repertoire)
    assert a.choose(x)[0] == b.choose(x)[0]


def test_another_repertoire_is_an_error_unless_allowed(arbitrator, small_repertoire):
    other = Repertoire.from_dict(
        {
            **small_repertoire.to_dict(),
            "primitives": {k: v[1:] for k, v in small_repertoire.to_dict()["primitives"].items()},
        }
    )
    with pytest.raises(ArbitratorError, match="does not match the arbitrator: its fingerprint"):
        arbitrator.check_repertoire(other, "other.json")
    warnings = arbitrator.check_repertoire(other, "other.json", allow_mismatch=True)
    assert len(warnings) == 1 and "other.json" in warnings[0]
    assert arbitrator.check_repertoire(small_repertoire, "r.json") == []


def test_another_sensor_layout_is_an_error_unless_allowed(arbitrator):
    data = LAYOUT.to_dict()
    data["rangefinders"]["range"] = 2.0
    other = SensorLayout.from_dict(data)
    with pytest.raises(ArbitratorError, match="differs from the arbitrator's"):
        arbitrator.check_sensors(other, "robot.yaml")
    assert arbitrator.check_sensors(other, "robot.yaml", allow_mismatch=True)


@pytest.mark.parametrize(
    ("edit", "needle"),
    [
        (lambda d: d.update(version=7), "version 7 is not supported"),
        (lambda d: d.update(format="evorbc-repertoire"), "not an arbitrator file"),
        (lambda d: d.update(kind="fuzzy"), "kind must be one of"),
        (lambda d: d.pop("network"), "missing key network"),
        (lambda d: d.update(mapping="spiral"), "mapping must be one of"),
        (lambda d: d["network"]["nodes"][0].update(activation="swish"), "unknown activation"),
        (
            lambda d: (
                d["sensors"]["rangefinders"]["angles_deg"].pop() and d.pop("sensors_fingerprint")
            ),
            "network has 10 inputs but the sensor layout gives 9",
        ),
        (lambda d: d["sensors"]["rangefinders"].update(range=3.0), "sensors_fingerprint"),
        (lambda d: d.pop("repertoire"), "repertoire.fingerprint is missing"),
    ],
)
def test_bad_files_give_one_line_errors(saved, edit, needle):
    rewrite(saved, edit)
    assert needle in load_error(saved)


def test_truncated_corrupt_and_missing(saved, tmp_path):
    text = saved.read_text()
    saved.write_text(text[: len(text) // 2])
    assert "truncated arbitrator file" in load_error(saved)
    saved.write_text("{]" + text)
    assert "corrupt" in load_error(saved)
    assert "no such arbitrator file" in load_error(tmp_path / "nope.json")


def test_standard_controller_outputs_genes():
    config = neat_config(n_outputs=5)
    spec = network_spec(random_genomes(config, 1, seed=3)[0], config)
    params = robot_type("4ws-5").parameter_specs(FourWSGeometry())
    controller = DirectController(
        ArbitratorFile("standard", "4ws-5", spec, LAYOUT, parameters=params)
    )
    genes = controller.genes(np.full(10, 0.5))
    assert genes.shape == (5,) and np.all(np.abs(genes) <= 1)
