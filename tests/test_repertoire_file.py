"""Repertoire files: round trip, CSV export and one-line errors for bad files."""

import csv
import json

import numpy as np
import pytest

from evorbc_ros.repertoire import Repertoire, RepertoireError


@pytest.fixture
def saved(tmp_path, small_repertoire):
    path = tmp_path / "r.json"
    small_repertoire.save(path)
    return path


def rewrite(path, edit):
    data = json.loads(path.read_text())
    edit(data)
    path.write_text(json.dumps(data))


def load_error(path):
    with pytest.raises(RepertoireError) as info:
        Repertoire.load(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path))
    return message


def test_round_trip_is_exact(saved, small_repertoire):
    loaded = Repertoire.load(saved)
    for field in ("genes", "behaviour", "heading", "quality"):
        np.testing.assert_array_equal(getattr(loaded, field), getattr(small_repertoire, field))
    assert loaded.parameters == small_repertoire.parameters
    assert loaded.archive == small_repertoire.archive
    assert loaded.fingerprint() == small_repertoire.fingerprint()
    data = json.loads(saved.read_text())
    assert data["format"] == "evorbc-repertoire" and data["version"] == 1
    assert data["summary"]["count"] == len(small_repertoire)
    assert set(data["algorithm"]) >= {
        "initial_batch",
        "batch_size",
        "iterations",
        "mutation_probability",
        "mutation_sigma",
    }


def test_csv_has_one_exact_row_per_primitive(tmp_path, small_repertoire):
    out = tmp_path / "r.csv"
    small_repertoire.to_csv(out)
    with open(out, newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(small_repertoire)
    assert list(rows[0])[:6] == [
        "x_m",
        "y_m",
        "heading_rad",
        "quality",
        "gene_speed",
        "gene_angle_fl",
    ]
    assert "speed_mps" in rows[0] and "angle_rr_rad" in rows[0]
    assert float(rows[3]["x_m"]) == small_repertoire.behaviour[3, 0]
    assert float(rows[3]["speed_mps"]) == pytest.approx(0.2 * small_repertoire.genes[3, 0])


def test_truncated_file(saved):
    saved.write_text(saved.read_text()[:2000])
    assert "truncated" in load_error(saved)


def test_corrupt_file(saved):
    text = saved.read_text()
    saved.write_text(text[:500] + "}{garbage" + text[500:])
    assert "corrupt" in load_error(saved)
    saved.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe")
    assert "not UTF-8" in load_error(saved)


def test_missing_file(tmp_path):
    assert "no such repertoire file" in load_error(tmp_path / "absent.json")


def test_wrong_version(saved):
    rewrite(saved, lambda d: d.update(version=99))
    assert "version 99 is not supported" in load_error(saved)


def test_not_a_repertoire(saved):
    rewrite(saved, lambda d: d.update(format="evorbc-arbitrator"))
    assert "not a repertoire file" in load_error(saved)
    saved.write_text("[1, 2, 3]")
    assert "JSON object" in load_error(saved)


def test_wrong_shapes(saved):
    rewrite(saved, lambda d: d["primitives"]["genes"][0].pop())
    assert "primitives.genes must be a rectangular array" in load_error(saved)


def test_row_counts_disagree(saved):
    rewrite(saved, lambda d: d["primitives"]["heading"].pop())
    assert "primitives.heading has shape" in load_error(saved)


def test_parameters_disagree_with_genes(saved):
    rewrite(saved, lambda d: d["parameters"].pop())
    assert "primitives.genes has shape" in load_error(saved)


def test_non_finite_values(saved):
    text = saved.read_text().replace('"quality": [', '"quality": [NaN, ', 1)
    saved.write_text(text)
    rewrite(saved, lambda d: d["primitives"]["quality"].pop())
    assert "NaN" in load_error(saved)


def test_genes_out_of_range(saved):
    rewrite(saved, lambda d: d["primitives"]["genes"][0].__setitem__(0, 1.5))
    assert "must lie in [-1.0, 1.0]" in load_error(saved)


def test_missing_and_mistyped_keys(saved):
    rewrite(saved, lambda d: d.pop("eval_time"))
    assert "missing key eval_time" in load_error(saved)
    rewrite(saved, lambda d: d.update(eval_time="2 s"))
    assert "eval_time must be int/float" in load_error(saved)
