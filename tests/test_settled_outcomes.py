"""The settled-outcomes file: written offline, read and checked onboard.

``evorbc-evolve settled`` computes what each primitive does once its actuators hold its
command, exactly as ``evaluate --adapt-expected settled`` does, and writes it beside the
repertoire for the arbitrator node (docs/design/adaptation.md, "What an observation is
compared with"; docs/design/file-formats.md, "Settled outcomes").
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from evorbc_ros.adaptation.settled import SettledError, load_settled, settled_path
from evorbc_ros.arbitration import Controller
from evorbc_ros.defaults import default_repertoire
from evorbc_ros.repertoire import Repertoire
from offline_evolution.cli import main
from offline_evolution.maze_task.adapting import expected_outcomes
from sim_bridge.robots import make_robot

SHIPPED = settled_path(default_repertoire())


def test_the_shipped_file_is_what_the_command_writes_and_the_model_computes(tmp_path, capsys):
    rep = Repertoire.load(default_repertoire())
    out = tmp_path / "4ws-5.settled.json"
    assert main(["settled", str(default_repertoire()), "--out", str(out)]) == 0
    assert capsys.readouterr().out.strip().endswith(f"258 settled outcomes of 4ws-5 -> {out}")
    assert out.read_bytes() == SHIPPED.read_bytes()
    rows = load_settled(SHIPPED, rep)
    model = expected_outcomes(rep, make_robot("4ws-5"), "settled")
    assert rows.shape == (len(rep), 3)
    np.testing.assert_array_equal(rows.view(np.int64), model.view(np.int64))  # same bits
    # The node's default: the file beside the repertoire.
    np.testing.assert_array_equal(Controller().settled_outcomes(), rows)
    assert settled_path("d/x.json").as_posix() == "d/x.settled.json"


def _edited(tmp_path, edit):
    data = json.loads(SHIPPED.read_text())
    edit(data)
    path = tmp_path / "edited.settled.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(
    ("edit", "problem"),
    [
        (lambda d: d.update(fingerprint="0" * 64), "made for another repertoire (fingerprint "
         "000000000000, the repertoire's is c7bb8df06d1b): make it again with evorbc-evolve "
         "settled REPERTOIRE"),
        (lambda d: d.update(format="evorbc-repertoire"), "not a settled-outcomes file"),
        (lambda d: d.update(version=2), "settled outcomes format version 2 is not supported"),
        (lambda d: d.update(count=257), "count must be the repertoire's 258 primitives, got 257"),
        (lambda d: d.update(eval_time=1.0), "eval_time must be the repertoire's 2.0 s, got 1.0"),
        (lambda d: d["outcomes"].pop("dy"), "outcomes must be an object of the columns dx, dy, "
         "dheading"),
        (lambda d: d["outcomes"]["dx"].pop(), "outcomes.dx must hold 258 values, one per "
         "primitive, got 257"),
        (lambda d: d["outcomes"]["dheading"].__setitem__(3, "0.1"), "outcomes.dheading must "
         "hold only numbers, it holds str"),
        (lambda d: d["outcomes"]["dy"].__setitem__(0, float("nan")), "outcomes.dy must be "
         "finite numbers"),
    ],
)  # fmt: skip
def test_a_bad_file_is_refused_in_one_line_naming_it(tmp_path, edit, problem):
    path = _edited(tmp_path, edit)
    with pytest.raises(SettledError) as e:
        load_settled(path, Repertoire.load(default_repertoire()))
    message = str(e.value)
    assert "\n" not in message and message.startswith(f"{path}: {problem}")


def test_a_missing_file_is_refused_in_one_line(tmp_path):
    with pytest.raises(SettledError, match=f"^{tmp_path / 'no.json'}: no such settled outcomes"):
        Controller().settled_outcomes(str(tmp_path / "no.json"))
