"""Checkpoints and outputs under bad input: nothing is lost, every error is one line.

A finished run survives a failed final write; a damaged or foreign checkpoint is named at
load and never deleted unless it is recognisably a checkpoint of the run's kind; an output
never overwrites an input or another output; a bad command-line value is blamed on its
option, a bad file value on the file and key.
"""

import json
import shutil

import numpy as np
import pytest

from evorbc_ros.repertoire import Repertoire
from offline_evolution.arbitrator.evolve import CHECKPOINT_KIND as NEAT_KIND
from offline_evolution.arbitrator.evolve import evolve
from offline_evolution.checkpoint import (
    CheckpointError,
    Interrupted,
    discard_checkpoint,
    load_checkpoint,
    save_checkpoint,
)
from offline_evolution.cli import main
from offline_evolution.repertoire.map_elites import generate_repertoire
from offline_evolution.repertoire.settings import load_settings
from offline_evolution.reporters import Reporter

TINY = ["--initial-batch", "20", "--batch-size", "10", "--iterations", "6", "--quiet"]


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "internal error" not in err, err
    return code, out, err.strip()


def one_line_error(capsys, *argv) -> str:
    code, _, err = run_cli(capsys, *argv)
    assert code == 1 and len(err.splitlines()) == 1, err
    return err


# -- a finished run outlives a failed final write ----------------------------------------


def test_a_failed_write_keeps_the_finished_repertoire_and_a_rerun_only_writes_it(
    tmp_path, capsys, monkeypatch
):
    folder, ckpt = tmp_path / "dd", tmp_path / "ck.npz"
    folder.mkdir()
    argv = ["repertoire", *TINY, "--checkpoint", ckpt, "--out", folder / "r.json"]
    original = Repertoire.save

    def folder_replaced_by_a_file(self, path):
        shutil.rmtree(folder)
        folder.write_text("")  # as if someone replaced the output folder during the run
        original(self, path)

    monkeypatch.setattr(Repertoire, "save", folder_replaced_by_a_file)
    err = one_line_error(capsys, *argv)
    assert f"the finished run is kept in {ckpt}" in err and "same command again" in err
    header, _ = load_checkpoint(ckpt)
    assert header["evaluations"] == 20 + 6 * 10  # complete, not the last periodic save

    monkeypatch.undo()
    folder.unlink()

    def step(run):
        raise AssertionError("the finished run was run again")

    monkeypatch.setattr("offline_evolution.repertoire.map_elites.MapElites.step", step)
    code, _, err = run_cli(capsys, *argv)
    assert code == 0, err
    assert not ckpt.exists()
    monkeypatch.undo()
    straight = tmp_path / "straight.json"
    assert run_cli(capsys, "repertoire", *TINY, "--out", straight)[0] == 0
    assert (
        json.loads((folder / "r.json").read_text())["primitives"]
        == json.loads(straight.read_text())["primitives"]
    )


def test_a_kept_arbitrator_checkpoint_is_complete_and_resumes_to_the_same_result(
    tmp_path, small_neat_file, small_repertoire
):
    from test_evolution import same, settings

    s = settings(small_neat_file, generations=2, repertoire=small_repertoire)
    ckpt = tmp_path / "a.checkpoint.json"

    resumes = []

    class Resumes(Reporter):
        def resumed(self, generations):
            resumes.append(generations)

    first = evolve(
        s, small_repertoire, checkpoint=ckpt, keep_checkpoint=True, reporters=[Resumes()]
    )
    assert resumes == []  # a fresh run
    data = json.loads(ckpt.read_text())
    assert data["population"]["generation"] == 2 and len(data["history"]) == 2
    again = evolve(
        s, small_repertoire, checkpoint=ckpt, keep_checkpoint=True, reporters=[Resumes()]
    )
    assert resumes == [2]  # said although only the post-evaluation was left
    same(first, again)
    assert again.selected_network == first.selected_network
    evolve(s, small_repertoire, checkpoint=ckpt)
    assert not ckpt.exists()


# -- checkpoint contents are checked at load ---------------------------------------------


def small_settings():
    return load_settings(robot="4ws-5", initial_batch=20, batch_size=10, iterations=6)


@pytest.fixture
def map_elites_checkpoint(tmp_path):
    ckpt = tmp_path / "ck.npz"
    polls = []
    with pytest.raises(Interrupted):
        generate_repertoire(
            small_settings(), checkpoint=ckpt, should_stop=lambda: polls.append(1) or len(polls) > 3
        )
    return ckpt


def edited(ckpt, header_change=None, **array_changes):
    header, arrays = load_checkpoint(ckpt)
    header.update(header_change or {})
    for name, change in array_changes.items():
        arrays[name] = change(arrays[name].copy())
    save_checkpoint(ckpt, header, arrays)


def nan_gene(a):
    a[0, 0] = np.nan
    return a


def gene_out_of_range(a):
    a[0, 0] = 1.5
    return a


@pytest.mark.parametrize(
    ("header_change", "array_changes", "reason"),
    [
        (None, {"solution": nan_gene}, "solution contains NaN or infinity"),
        (None, {"solution": gene_out_of_range}, "solution (genes) must lie in [-1.0, 1.0]"),
        (None, {"measures": lambda a: a + 100.0}, "measures (behaviour) must lie inside"),
        (None, {"heading": lambda a: a[:-1]}, "heading has shape"),
        (None, {"objective": lambda a: a * 1e6}, "objective (quality) must lie in [0, 1]"),
        (None, {"heading": lambda a: a + 1e6}, "heading must lie within 1000 rad"),
        ({"evaluations": "abc"}, {}, "evaluations must be a whole number"),
        ({"evaluations": 10**9}, {}, "evaluations must be a whole number from 0 to 80"),
        ({"emitter": {"x": 1}}, {}, "emitter must hold the state of its random generator"),
        ({"settings": "x"}, {}, "settings missing"),
    ],
)
def test_a_map_elites_checkpoint_with_impossible_contents_is_refused_at_load(
    map_elites_checkpoint, header_change, array_changes, reason
):
    edited(map_elites_checkpoint, header_change, **array_changes)
    with pytest.raises(CheckpointError) as info:
        generate_repertoire(small_settings(), checkpoint=map_elites_checkpoint)
    assert str(info.value).startswith(f"{map_elites_checkpoint}: not a usable checkpoint ({reason}")
    assert info.value.discardable and map_elites_checkpoint.exists()


def test_the_cli_names_a_bad_checkpoint_keeps_it_and_restart_discards_it(
    tmp_path, capsys, map_elites_checkpoint
):
    edited(map_elites_checkpoint, solution=nan_gene)
    argv = [
        "repertoire",
        *TINY,
        "--checkpoint",
        map_elites_checkpoint,
        "--out",
        tmp_path / "r.json",
    ]
    err = one_line_error(capsys, *argv)
    assert f"{map_elites_checkpoint}: not a usable checkpoint (solution contains NaN" in err
    assert err.endswith("use --restart to discard it") and map_elites_checkpoint.exists()
    assert run_cli(capsys, *argv, "--restart")[0] == 0
    assert Repertoire.load(tmp_path / "r.json").algorithm["evaluations"] == 80


@pytest.fixture
def neat_checkpoint(tmp_path, small_neat_file, small_repertoire):
    from test_evolution import settings

    s = settings(small_neat_file, generations=3, repertoire=small_repertoire)
    ckpt = tmp_path / "a.checkpoint.json"
    with pytest.raises(Interrupted):
        evolve(s, small_repertoire, checkpoint=ckpt, should_stop=lambda: True)
    return s, ckpt


@pytest.mark.parametrize(
    ("path", "value", "reason"),
    [
        (["best"], {"x": 1}, "best.key is missing"),
        (["settings"], "x", "settings missing"),
        (["population", "generation"], "abc", "population.generation must be a whole number"),
        (["population", "genomes", 0, "nodes", 0, "bias"], "x", "nodes[0].bias must be a number"),
        (["population", "genomes", 0, "nodes", 0, "activation"], "zap", "activation must be one"),
        (["population", "species", 0, "members"], [10**6], "genomes not in the population"),
        (["hall_of_fame", "top"], [{"key": 1}], "hall_of_fame.top[0].fitness is missing"),
        (["history", 0, "best"], None, "history[0].best must be a number"),
        (["history"], [], "history has 0 generations, the population 1"),
        (["elapsed"], "soon", "elapsed must be a number"),
    ],
)
def test_a_neat_checkpoint_with_impossible_contents_is_refused_in_one_line(
    neat_checkpoint, small_repertoire, path, value, reason
):
    s, ckpt = neat_checkpoint
    data = json.loads(ckpt.read_text())
    target = data
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    ckpt.write_text(json.dumps(data))
    with pytest.raises(CheckpointError) as info:
        evolve(s, small_repertoire, checkpoint=ckpt)
    message = str(info.value)
    assert message.startswith(f"{ckpt}: not a usable checkpoint (") and reason in message
    assert "\n" not in message and info.value.discardable and ckpt.exists()


# -- an output never overwrites an input or another output ---------------------------------


def test_export_csv_refuses_to_overwrite_its_input(tmp_path, capsys, small_repertoire):
    rep = tmp_path / "myrep.csv"  # a repertoire JSON with a .csv name
    small_repertoire.save(rep)
    before = rep.read_bytes()
    err = one_line_error(capsys, "export-csv", rep)
    assert err.endswith(f"the default --out {rep} is the same file as REPERTOIRE; use another file")
    json_rep = tmp_path / "r.json"
    small_repertoire.save(json_rep)
    err = one_line_error(capsys, "export-csv", json_rep, "--out", tmp_path / "." / "r.json")
    assert "--out" in err and "same file as REPERTOIRE" in err
    assert rep.read_bytes() == before and Repertoire.load(json_rep)


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--csv", "same.json"], "--csv same.json is the same file as --out"),
        (["--plot", "same.json"], "--plot same.json is the same file as --out"),
        (["--checkpoint", "same.json"], "--checkpoint same.json is the same file as --out"),
        (["--csv", "c.csv", "--plot", "c.csv"], "--csv c.csv is the same file as --plot"),
    ],
)
def test_repertoire_outputs_must_be_distinct_files(tmp_path, capsys, monkeypatch, extra, needle):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "same.json").write_text("precious")
    assert needle in one_line_error(capsys, "repertoire", *TINY, "--out", "same.json", *extra)
    assert (tmp_path / "same.json").read_text() == "precious"


def test_repertoire_output_over_its_settings_file_is_refused(tmp_path, capsys):
    cfg = tmp_path / "c.yaml"
    cfg.write_text("robot: 4ws-3\n")
    err = one_line_error(capsys, "repertoire", "--config", cfg, *TINY, "--out", cfg)
    assert f"--config {cfg} is the same file as --out" in err
    assert cfg.read_text() == "robot: 4ws-3\n"


# -- a file that is not a checkpoint is named as such and never deleted -----------------------


@pytest.mark.parametrize("content", [b"12345678", b'{"format": "evorbc-repertoire"}'])
def test_a_file_that_is_no_checkpoint_is_refused_and_restart_leaves_it_alone(
    tmp_path, capsys, content
):
    precious = tmp_path / "precious.json"
    precious.write_bytes(content)
    argv = ["repertoire", *TINY, "--out", tmp_path / "new.json", "--checkpoint", precious]
    err = one_line_error(capsys, *argv)
    assert err.endswith(
        f"{precious}: not a checkpoint (not an .npz archive); choose another --checkpoint"
    )
    assert "pickle" not in err and "--restart" not in err
    err = one_line_error(capsys, *argv, "--restart")
    assert f"{precious}: not a MAP-Elites checkpoint, so --restart does not delete it" in err
    assert precious.read_bytes() == content and not (tmp_path / "new.json").exists()


def test_a_checkpoint_of_another_kind_is_not_discarded(tmp_path, map_elites_checkpoint):
    with pytest.raises(CheckpointError, match="not a NEAT checkpoint") as info:
        discard_checkpoint(map_elites_checkpoint, NEAT_KIND, "NEAT checkpoint")
    assert not info.value.discardable and map_elites_checkpoint.exists()
    neat = tmp_path / "n.json"
    neat.write_text(json.dumps({"kind": NEAT_KIND, "population": "damaged"}))
    discard_checkpoint(neat, NEAT_KIND, "NEAT checkpoint")
    assert not neat.exists()


def test_a_pickle_in_a_checkpoint_is_named_without_numpys_advice(tmp_path):
    ckpt = tmp_path / "p.npz"
    np.savez(ckpt, __header__=np.array(json.dumps({"kind": "x"})), solution=np.array([{}]))
    with pytest.raises(CheckpointError) as info:
        load_checkpoint(ckpt)
    assert str(info.value) == f"{ckpt}: not a usable checkpoint (it holds pickled objects)"


# -- the option or the file and key is named --------------------------------------


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--bin-size", "1e-9", "--bin-size: must be >= 0.0001, got 1e-09"),
        ("--eval-time", "0.05", "--eval-time: must be >= 0.1, got 0.05"),
        ("--batch-size", "0", "--batch-size: must be >= 1, got 0"),
        ("--initial-batch", "0", "--initial-batch: must be >= 1, got 0"),
        ("--eval-time", "2.05", "--eval-time: must be a positive multiple of the 0.1 s"),
        ("--metric", "circular+tilt", "--metric: must suit robot 4ws-5 (metric 'circular+tilt'"),
    ],
)
def test_a_bad_option_value_is_blamed_on_the_option(tmp_path, capsys, option, value, message):
    argv = ["repertoire", *TINY, "--robot", "4ws-5", option, value, "--out", tmp_path / "r.json"]
    err = one_line_error(capsys, *argv)
    assert err.startswith(f"evorbc-evolve: error: {message}") and "yaml" not in err
    assert list(tmp_path.iterdir()) == []  # no output, no checkpoint left behind


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("eval_time: 2.05", "eval_time must be a positive multiple of the 0.1 s control period"),
        ("metric: circular+tilt", "metric must suit robot 4ws-5"),
    ],
)
def test_a_setting_that_does_not_suit_the_robot_names_the_file_and_key(
    tmp_path, capsys, line, message
):
    cfg = tmp_path / "c.yaml"
    base = {
        "robot": "4ws-5",
        "metric": "circular",
        "bin_size": 0.04,
        "eval_time": 2.0,
        "initial_batch": 10,
        "batch_size": 10,
        "iterations": 1,
    }
    key, value = line.split(": ")
    base[key] = value if key == "metric" else float(value)
    cfg.write_text("".join(f"{k}: {v}\n" for k, v in base.items()))
    err = one_line_error(capsys, "repertoire", "--config", cfg, "--out", tmp_path / "r.json")
    assert err.startswith(f"evorbc-evolve: error: {cfg}: {message}")


def test_a_run_that_keeps_no_primitive_writes_nothing_and_says_so(tmp_path, capsys, monkeypatch):
    import offline_evolution.repertoire.map_elites as map_elites

    real = map_elites.generate_repertoire

    def nothing_kept(*args, **kwargs):  # as if every primitive left the archive's range
        rep = real(*args, **kwargs)
        keep = np.zeros(len(rep), dtype=bool)
        return Repertoire(rep.robot, rep.parameters, rep.genes[keep], rep.behaviour[keep],
                          rep.heading[keep], rep.quality[keep], rep.metric, rep.eval_time,
                          rep.bin_size, rep.seed, rep.archive, rep.algorithm)  # fmt: skip

    monkeypatch.setattr(map_elites, "generate_repertoire", nothing_kept)
    out = tmp_path / "r.json"
    code, _, err = run_cli(capsys, "repertoire", *TINY, "--out", out)
    assert code == 1 and err.startswith("evorbc-evolve: error: no primitive was kept after")
    assert not out.exists() and not (tmp_path / "r.json.checkpoint.npz").exists()
