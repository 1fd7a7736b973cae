"""The controller-kind registry: one record per kind, looked up once, files unchanged."""

import copy
import json
import pickle

import pytest

from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
from evorbc_ros.controller_kinds import EVORBC, KINDS, STANDARD, controller_kind, direct_genes
from evorbc_ros.defaults import default_arbitrator


def test_a_name_gives_its_record_and_a_record_itself():
    assert controller_kind("evorbc") is EVORBC and controller_kind("standard") is STANDARD
    assert controller_kind(STANDARD) is STANDARD
    assert list(KINDS) == ["evorbc", "standard"]
    assert EVORBC.n_outputs(11) == 2 and STANDARD.n_outputs(11) == 11


@pytest.mark.parametrize("bad", ["fuzzy", None, 3, "EvoRBC"])
def test_an_unknown_kind_is_one_line_naming_the_source_and_the_kinds(bad):
    with pytest.raises(ValueError) as e:
        controller_kind(bad, "run.json: kind")
    message = str(e.value)
    assert "\n" not in message
    assert message.startswith("run.json: kind: kind must be one of evorbc, standard, got ")


def test_workers_and_copies_get_the_same_record():
    for kind in KINDS.values():
        assert pickle.loads(pickle.dumps(kind)) is kind
        assert copy.deepcopy(kind) is kind


def test_code_written_against_the_names_keeps_working():
    assert EVORBC == "evorbc" and STANDARD != "evorbc" and EVORBC != STANDARD
    assert f"{STANDARD} controller" == "standard controller"
    assert {EVORBC: 1}["evorbc"] == 1


def test_the_shipped_file_round_trips_bit_for_bit(tmp_path):
    arb = ArbitratorFile.load(default_arbitrator())
    assert arb.kind is EVORBC
    out = tmp_path / "a.json"
    arb.save(out)
    assert json.loads(out.read_text()) == json.loads(default_arbitrator().read_text())
    assert ArbitratorFile(**{**vars(arb), "kind": "evorbc"}).kind is EVORBC
    with pytest.raises(ArbitratorError, match="kind must be one of evorbc, standard"):
        ArbitratorFile(**{**vars(arb), "kind": "fuzzy"})


def test_standard_genes_map_outputs_onto_the_gene_range():
    assert direct_genes([0.0, 0.5, 1.0, 2.0]).tolist() == [-1.0, 0.0, 1.0, 1.0]
    assert direct_genes([0.5, float("nan")]) is None
