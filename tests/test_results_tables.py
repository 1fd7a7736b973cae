"""docs/results regenerates: raw run files -> compact tables -> the docs' tables and curves.

A small real run folder (the shipped A1 controller's run file and a real 4ws-5 evaluation
at 1 start per maze) is compacted, and the screening table and fitness curve made from the
tables must show the raw files' figures.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from PIL import Image

from offline_evolution.results import curves, extract, summaries
from offline_evolution.results.tables import TableError

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "evorbc_ros" / "evorbc_ros" / "data"
RESULTS = ROOT / "docs" / "results"


@pytest.fixture(scope="module")
def raw(tmp_path_factory) -> Path:
    """``generalise/k-seed1.*``: a run file with its history and a paper-maze report."""
    root = tmp_path_factory.mktemp("runs")
    (root / "generalise").mkdir()
    run = root / "generalise" / "k-seed1.arbitrator.json"
    shutil.copy(DATA / "4ws-5-paper.arbitrator.json", run)
    for suite in ("paper", "held"):
        subprocess.run(
            [sys.executable, "-P", "-m", "offline_evolution.cli", "evaluate",
             "--arbitrator", str(run), "--repertoire", str(DATA / "4ws-5.repertoire.json"),
             "--starts", "1", "--perturb", "none",
             "--out", str(root / "generalise" / f"k-seed1.{suite}.json")],
            check=True, cwd=ROOT, capture_output=True,
        )  # fmt: skip
    return root


def test_tables_regenerate_the_screening_table_and_curve(raw, tmp_path):
    out = tmp_path / "results"
    counts = extract.extract(raw, out, ["generalise/k-seed1"])
    data = json.loads((raw / "generalise" / "k-seed1.arbitrator.json").read_text())
    history = data["evolution"]["history"]
    assert counts["histories/generalise/k-seed1.csv"] == len(history)
    report = json.loads((raw / "generalise" / "k-seed1.paper.json").read_text())
    table = summaries.screening_table(out)
    row = next(line for line in table.splitlines() if line.startswith("| k-seed1 |"))
    assert f"{report['overall']['reach_rate']:.0%}" in row
    assert "none (paper protocol)" in row
    curve = curves.history(out, "generalise/k-seed1")
    assert [c["generation"] for c in curve] == [h["generation"] for h in history]
    assert curve[-1]["best_so_far"] == pytest.approx(max(h["best"] for h in history), rel=1e-3)
    curves.plot_run(out, "generalise/k-seed1", tmp_path / "curve.png")
    with Image.open(tmp_path / "curve.png") as im:
        assert im.mode == "P"  # the palette PNG of save_figure
    kept = json.loads((out / "controllers" / "k-seed1.arbitrator.json").read_text())
    assert kept["network"] == data["network"] and kept["evolution"]["history"] == []


def test_a_run_continued_shares_its_history(raw, tmp_path):
    data = json.loads((raw / "generalise" / "k-seed1.arbitrator.json").read_text())
    data["evolution"]["history"] = data["evolution"]["history"][:10]
    data["evolution"]["generations"] = 10
    copy = tmp_path / "runs"
    shutil.copytree(raw, copy)
    (copy / "generalise" / "k-seed1-g10.arbitrator.json").write_text(json.dumps(data))
    out = tmp_path / "results"
    extract.extract(copy, out)
    assert not (out / "histories" / "generalise" / "k-seed1-g10.csv").exists()
    assert len(curves.history(out, "generalise/k-seed1-g10")) == 10


def test_the_committed_tables_make_the_docs_tables():
    table = summaries.screening_table(RESULTS)
    assert "| fresh-k10-g8-rnn-path-seed1 |" in table and "**90.4%**" in table
    ship = summaries.screening_table(RESULTS, "generalise/ship/")
    assert "| 4ws-5-p8-p1mr-seed4 |" in ship and "**95.9%**" in ship
    assert len(curves.history(RESULTS, "generalise/ship/4ws-5-p8-p1mr-seed4")) == 1000


def test_bad_input_is_one_line(tmp_path):
    with pytest.raises(TableError, match=r"arbitrator-runs\.csv"):
        summaries.screening_table(tmp_path)
    result = subprocess.run(
        [sys.executable, "-P", "-m", "offline_evolution.results", "--results", str(tmp_path),
         "curve", "nothing", "--out", str(tmp_path / "x.png")],
        cwd=ROOT, capture_output=True, text=True,
    )  # fmt: skip
    assert result.returncode != 0 and "Traceback" not in result.stderr
    assert "arbitrator-runs.csv" in result.stderr


def test_gzipped_tables_round_trip_and_refuse_a_bomb(tmp_path, monkeypatch):
    from offline_evolution.results import tables

    rows = [{"report": f"generalise/long-report-name-{k % 3}", "maze": k} for k in range(200)]
    path = tmp_path / "t.csv.gz"
    assert tables.write_table(path, ["report", "maze"], rows) == 200
    first = path.read_bytes()
    tables.write_table(path, ["report", "maze"], rows)
    assert path.read_bytes() == first  # the same rows, the same bytes
    back = tables.read_table(path, ["report", "maze"])
    assert [r["maze"] for r in back] == [str(k) for k in range(200)]
    monkeypatch.setattr(tables, "MAX_TABLE_BYTES", 1000)
    with pytest.raises(TableError, match=r"t\.csv\.gz: more than 1000 bytes"):
        tables.read_table(path)
    broken = tmp_path / "b.csv.gz"
    broken.write_bytes(b"not gzip at all")
    with pytest.raises(TableError, match=r"b\.csv\.gz: cannot read the table"):
        tables.read_table(broken)
