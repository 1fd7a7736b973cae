"""The compact result table of a study (offline_evolution/study/table.py, docs/study.md):
the report made from it is the report made from the results folder, and a malformed
table is refused in one line naming the file and the key."""

import base64
import json
import zlib

import numpy as np
import pytest
from study_helpers import TINY_STUDY, run_study

from offline_evolution.study.cli import main as study_main
from offline_evolution.study.folder import load_results
from offline_evolution.study.results import (
    CHOSEN_BINS,
    OUTPUT_BINS,
    ExampleRepertoire,
    RunResult,
    SelectionCounts,
    SettingResults,
)
from offline_evolution.study.spec import load_study
from offline_evolution.study.table import pack_column, read_table, unpack_column, write_table

#: The tiny study with every figure an EvoRBC study can draw, the selection heatmaps too.
ALL_FIGURES = TINY_STUDY + "figures: [curves, boxplots, repertoires, selection]\n"


def _tiny(tmp_path):
    path = tmp_path / "tiny.yaml"
    path.write_text(ALL_FIGURES)
    return load_study(path)


def _synthetic(study) -> list[SettingResults]:
    """Two runs of the tiny study's one setting, with figures' data, made up here."""
    rng = np.random.default_rng(4)
    summary = {"post_fitness": 0.3, "generations": 20}
    summary["repertoire"] = {"count": 5, "mean_quality": 0.9}
    runs = [
        RunResult(
            seed=seed,
            generations=20,
            seconds=30.5 + seed,
            cpu_seconds=12.25,
            machine="x86_64, 2 cores",
            summary={**summary, "best_fitness": 0.4 + seed / 10},
            evolution_seconds=20.0,
            best_so_far=np.maximum.accumulate(rng.random(20)),
        )
        for seed in (1, 2)
    ]
    ints = {k: rng.integers(-900, 900, 5) for k in ("x", "y", "heading", "quality")}
    example = ExampleRepertoire.from_columns(1, "circular", 0.04, [-0.1, -0.1], [0.1, 0.1], ints)
    selection = SelectionCounts(
        2, 0.09, rng.integers(0, 9, (OUTPUT_BINS, OUTPUT_BINS)),
        rng.integers(0, 9, (CHOSEN_BINS, CHOSEN_BINS)),
    )  # fmt: skip
    ((sid, values),) = study.settings()
    return [SettingResults(sid, values, runs, example, selection)]


def _assert_same(a: list[SettingResults], b: list[SettingResults]) -> None:
    """Every number the report and its figures use is equal."""
    assert len(a) == len(b)
    for x, y in zip(a, b, strict=True):
        assert (x.setting_id, x.values) == (y.setting_id, y.values)
        for r, q in zip(x.runs, y.runs, strict=True):
            assert np.array_equal(r.best_so_far, q.best_so_far)
            fields = ("seed", "generations", "seconds", "cpu_seconds", "machine", "summary")
            assert [getattr(r, f) for f in fields] == [getattr(q, f) for f in fields]
            assert r.evolution_seconds == q.evolution_seconds
        for name in ("behaviour", "heading", "quality"):
            assert np.array_equal(getattr(x.example, name), getattr(y.example, name))
        assert (x.example.archive, x.example.bin_size) == (y.example.archive, y.example.bin_size)
        assert (x.selection.runs, x.selection.reach) == (y.selection.runs, y.selection.reach)
        assert np.array_equal(x.selection.outputs, y.selection.outputs)
        assert np.array_equal(x.selection.chosen, y.selection.chosen)


def test_a_table_reads_back_every_number_it_was_written_with(tmp_path):
    study = _tiny(tmp_path)
    settings = _synthetic(study)
    path = tmp_path / "tiny.results.json"
    write_table(study, settings, path, "results", "commit abc1234 under results")
    header, back = read_table(path, study)
    assert header == {"results": "results", "source": "commit abc1234 under results",
                      "replay_runs": None}  # fmt: skip
    _assert_same(settings, back)
    # The history is run-length coded: a value per change, not per generation.
    row = json.loads(path.read_text())["settings"][0]["runs"][0]["best_so_far"]
    assert row["length"] == 20 and len(row["at"]) == len(np.unique(settings[0].runs[0].best_so_far))


@pytest.mark.slow
def test_the_report_of_the_table_is_the_report_of_the_results_folder(serial_results, tmp_path):
    study = tmp_path / "tiny.yaml"
    study.write_text(ALL_FIGURES)
    table = tmp_path / "tiny.results.json"
    assert run_study("compact", study, "--results", serial_results, "--out", table).returncode == 0
    for results, out in ((serial_results, "folder"), (table, "table")):
        done = run_study("report", study, "--results", results, "--out", tmp_path / out)
        assert done.returncode == 0, done.stderr
    folder, compact = (
        (tmp_path / d / "tiny.md").read_text().splitlines() for d in ("folder", "table")
    )
    # Only the sentence that says where the page comes from differs.
    assert folder[2].startswith("The paper's") and compact[2].startswith("The paper's")
    assert folder[:2] + folder[3:] == compact[:2] + compact[3:]
    assert "from the study's compact result table alone" in compact[2]
    assert f"compacted by `evorbc-study compact tiny --results {serial_results}" in compact[2]
    names = ("tiny-fitness.png", "tiny-boxplot.png", "tiny-repertoires.png", "tiny-selection.png")
    for name in names:
        assert f"]({name})" in "\n".join(compact)
        # Drawn from the same numbers, so the same pixels.
        assert (tmp_path / "folder" / name).read_bytes() == (tmp_path / "table" / name).read_bytes()
    # And the numbers are the folder's.
    _assert_same(load_results(load_study(study), serial_results, selection=True),
                 read_table(table, load_study(study))[1])  # fmt: skip


def _refused(tmp_path, capsys, edit) -> str:
    """The one-line error of ``report`` on the synthetic table after ``edit(data)``."""
    study = _tiny(tmp_path)
    path = tmp_path / "tiny.results.json"
    write_table(study, _synthetic(study), path, "results")
    data = json.loads(path.read_text())
    edit(data)
    path.write_text(json.dumps(data))
    code = study_main(["report", str(tmp_path / "tiny.yaml"), "--results", str(path),
                       "--out", str(tmp_path / "out")])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "out" / "tiny.md").exists()
    return err.strip().removeprefix(f"evorbc-study: error: {path}: ")


def _set(data, path: str, value):
    """``data`` with the value at a dotted path (list indices as numbers) replaced."""
    *parents, last = [int(p) if p.isdigit() else p for p in path.split(".")]
    for p in parents:
        data = data[p]
    if value is _set:
        del data[last]
    else:
        data[last] = value


@pytest.mark.parametrize(
    ("where", "value", "message"),
    [
        ("format", "csv", "format: expected 'evorbc-study-results', got 'csv'"),
        ("version", 1, "version: expected 2, got 1"),
        ("study", "metrics", "study: expected 'tiny' (the study asked for), got 'metrics'"),
        ("settings.0.id", "approach-standard", "settings[0].id: expected 'approach-evorbc'"),
        ("settings.0.runs.1.summary.best_fitness", "1.2",
         "settings[0].runs[1].summary.best_fitness: expected a number, got '1.2'"),
        ("settings.0.runs.0.seed", _set, "settings[0].runs[0].seed: missing"),
        ("settings.0.runs.0.best_so_far.at", [0, 5, 3],
         "settings[0].runs[0].best_so_far.at: expected increasing generations"),
        ("settings.0.example.quality", pack_column([1, 2]),
         "settings[0].example.quality: expected 5 integers packed as base64 of zlib int32"),
        ("settings.0.example.x", [1, 2, 3, 4, 5], "settings[0].example.x: expected str"),
        ("settings.0.example.y", "not base64!", "settings[0].example.y: expected 5 integers"),
        ("settings.0.example.count", -1, "settings[0].example.count: expected 0 to 1000000"),
        ("settings.0.selection.chosen", [[1, 2], [3, 4]],
         "settings[0].selection.chosen: expected 40 x 40 counts >= 0"),
        ("settings", {}, "settings: expected list, got {}"),
    ],
)  # fmt: skip
def test_a_malformed_table_is_refused_naming_the_file_and_key(
    tmp_path, capsys, where, value, message
):
    assert _refused(tmp_path, capsys, lambda d: _set(d, where, value)).startswith(message)


def test_a_file_that_is_no_json_is_refused_in_one_line(tmp_path, capsys):
    _tiny(tmp_path)
    path = tmp_path / "tiny.results.json"
    path.write_bytes(b"\x89PNG\r\n")
    code = study_main(["report", str(tmp_path / "tiny.yaml"), "--results", str(path)])
    err = capsys.readouterr().err
    assert code == 1 and err.startswith(f"evorbc-study: error: {path}: not a JSON result table")
    assert err.count("\n") == 1


def test_replay_runs_belong_to_compact_not_to_a_table(tmp_path, capsys):
    study = _tiny(tmp_path)
    path = tmp_path / "tiny.results.json"
    write_table(study, _synthetic(study), path, "results")
    code = study_main(["report", str(tmp_path / "tiny.yaml"), "--results", str(path),
                       "--replay-runs", "1", "--out", str(tmp_path / "out")])  # fmt: skip
    assert code == 1 and "evorbc-study compact --replay-runs" in capsys.readouterr().err


def test_a_packed_column_inflates_no_more_than_its_count():
    """A hostile column (a zlib bomb, trailing bytes, another count) is refused, not inflated."""
    values = [-(2**31), -1, 0, 7, 2**31 - 1]
    assert unpack_column(pack_column(values), 5).tolist() == values
    bomb = base64.b64encode(zlib.compress(bytes(400_000_000), 9)).decode()
    assert unpack_column(bomb, 5) is None
    assert unpack_column(pack_column(values), 4) is None
    assert unpack_column(pack_column(values) + "AAAA", 5) is None
    with pytest.raises(ValueError):
        pack_column([2**31])
