"""Files that parse but mean nothing a run writes are refused in one line (docs/design.md 12, 13).

Repertoires (behaviours outside the archive, two primitives in a cell, qualities the metric
cannot give, absurd headings, cells and times, strings where numbers belong), arbitrator
files (versions, lists, sizes, cycles) and checkpoints (zip bombs, dtypes, versions, NEAT
populations whose species and counters do not add up): each names the file and the key,
the CLI exits 1 without a traceback, and nothing is written.
"""

import copy
import io
import itertools
import json
import math
import os
import re
import zipfile
from pathlib import Path

import numpy as np
import pytest
import test_errors_checkpoints as checkpoint_tests
from test_errors_checkpoints import TINY, edited, one_line_error, small_settings

from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
from evorbc_ros.network import NetworkSpec
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.repertoire_checks import HEADING_LIMIT, QUALITY_RANGES
from offline_evolution.arbitrator.evolve import CHECKPOINT_KIND as NEAT_KIND
from offline_evolution.arbitrator.evolve import evolve
from offline_evolution.checkpoint import (
    CheckpointError,
    checkpoint_kind,
    load_checkpoint,
    save_checkpoint,
)
from offline_evolution.quality import METRICS
from offline_evolution.repertoire.map_elites import generate_repertoire
from sim_bridge.robots.base import PrimitiveOutcome

DATA = Path(__file__).resolve().parent.parent / "evorbc_ros" / "evorbc_ros" / "data"
ARBITRATOR = DATA / "4ws-5.arbitrator.json"

#: The fixtures of tests/test_errors_checkpoints.py: a stopped MAP-Elites and NEAT run.
map_elites_checkpoint = checkpoint_tests.map_elites_checkpoint
neat_checkpoint = checkpoint_tests.neat_checkpoint

# -- repertoires ------------------------------------------------------------------------


def _behaviours(t, f):
    t["primitives"]["behaviour"] = [f(b) for b in t["primitives"]["behaviour"]]


def _one_just_outside(t):
    t["primitives"]["behaviour"][0][0] = t["archive"]["high"][0] + 1e-6


def _two_in_one_cell(t):
    for column in t["primitives"].values():
        column.append(copy.deepcopy(column[0]))


def _set(*path_and_value):
    *path, value = path_and_value

    def change(t):
        for key in path[:-1]:
            t = t[key]
        t[path[-1]] = value

    return change


REPERTOIRE_CASES = {
    "all-outside": (lambda t: _behaviours(t, lambda b: [b[0] + 10, b[1]]), "primitives.behaviour["),
    "one-just-outside": (_one_just_outside, "primitives.behaviour[0] is"),
    "two-in-one-cell": (_two_in_one_cell, "are in the same archive cell"),
    "quality-5": (_set("primitives", "quality", 0, 5.0), "quality[0] is 5.0, outside [0, 1]"),
    "quality-negative": (_set("primitives", "quality", 0, -0.5), "quality[0] is -0.5, outside"),
    "heading-1e6": (_set("primitives", "heading", 0, 1e6), "primitives.heading[0] is 1000000.0"),
    "bin-size-1e-300": (_set("bin_size", 1e-300), "EVORBC_MAX_ARCHIVE_CELLS"),
    "eval-time-1e300": (_set("eval_time", 1e300), "eval_time must be in (0, 3600] s"),
    "quality-strings": (
        lambda t: t["primitives"].update(quality=[str(q) for q in t["primitives"]["quality"]]),
        "primitives.quality must hold only numbers, it holds str",
    ),
    "quality-booleans": (
        lambda t: t["primitives"].update(quality=[True] * len(t["primitives"]["quality"])),
        "primitives.quality must hold only numbers, it holds bool",
    ),
    "genes-strings": (_set("primitives", "genes", 0, 0, "0.5"), "primitives.genes must hold only"),
    "dims-inconsistent": (_set("archive", "dims", [40, 40]), "archive.dims[0] is 40 cells"),
    "version-float": (_set("version", 1.0), "version must be a whole number"),
    "version-true": (_set("version", True), "version must be a whole number"),
    "cvt-too-many-cells": (
        lambda t: t["archive"].update(kind="cvt", cells=10**6),
        "archive.cells is 1000000, more than",
    ),
}


@pytest.mark.parametrize("case", REPERTOIRE_CASES)
def test_a_repertoire_no_run_writes_is_refused_naming_the_key(
    tmp_path, capsys, small_repertoire, case
):
    change, needle = REPERTOIRE_CASES[case]
    tree = copy.deepcopy(small_repertoire.to_dict())  # to_dict shares the archive dict
    tree["metric"] = "circular"
    change(tree)
    path, out = tmp_path / "r.json", tmp_path / "r.csv"
    path.write_text(json.dumps(tree))
    err = one_line_error(capsys, "export-csv", path, "--out", out)
    assert err.startswith(f"evorbc-evolve: error: {path}: ") and needle in err, err
    assert not out.exists()


def test_the_primitives_are_counted_before_any_is_read(
    tmp_path, capsys, small_repertoire, monkeypatch
):
    path = tmp_path / "r.json"
    small_repertoire.save(path)
    monkeypatch.setenv("EVORBC_MAX_PRIMITIVES", "10")

    def no_per_primitive_work(*args, **kw):
        raise AssertionError("columns were converted before the count was checked")

    monkeypatch.setattr("evorbc_ros.repertoire.number_column", no_per_primitive_work)
    err = one_line_error(capsys, "export-csv", path, "--out", tmp_path / "r.csv")
    n = len(small_repertoire)
    assert f"{path}: {n} primitives in the file, more than the limit of 10" in err
    assert "EVORBC_MAX_PRIMITIVES=" in err


def test_each_metric_range_is_the_one_its_qualities_lie_in():
    assert {name: (m.low, m.high) for name, m in METRICS.items()} == QUALITY_RANGES
    rng = np.random.default_rng(3)
    n = 20_000
    x, y = rng.normal(0, 1, n), rng.normal(0, 1, n)
    reach = np.hypot(x, y)
    outcome = PrimitiveOutcome(
        x=x,
        y=y,
        heading=rng.uniform(-50, 50, n),
        path=reach * rng.uniform(1, 3, n),
        max_tilt=rng.uniform(0, np.radians(45), n),
    )
    for name, metric in METRICS.items():
        q = metric.function(outcome)
        assert metric.low <= q.min() and q.max() <= metric.high, name


def test_the_shipped_repertoires_pass_every_check():
    for name in ("4ws-5", "hexapod", "a1"):
        rep = Repertoire.load(DATA / f"{name}.repertoire.json")
        assert np.abs(rep.heading).max() < HEADING_LIMIT


def test_a_generated_cvt_repertoire_passes_every_check(tmp_path):
    settings = small_settings()
    settings = type(settings)(**{**settings.as_dict(), "archive": "cvt"})
    path = tmp_path / "cvt.json"
    generate_repertoire(settings).save(path)
    assert Repertoire.load(path).archive["kind"] == "cvt"


# -- arbitrator files and networks --------------------------------------------------------


def _arbitrator(tmp_path, change):
    tree = json.loads(Path(ARBITRATOR).read_text())
    change(tree)
    path = tmp_path / "a.json"
    path.write_text(json.dumps(tree))
    return path


def _chain(n):
    def change(t):
        net = t["network"]
        net.pop("recurrent", None)  # feed-forward: the order matters
        net["connections"] = []  # the shipped network is recurrent, with cycles
        nodes = [
            {"key": 1000 + i, "bias": 0.0, "response": 1.0, "activation": "identity",
             "aggregation": "sum"}
            for i in range(n)
        ]  # fmt: skip
        link = [net["inputs"][0], *range(1000, 1000 + n), net["outputs"][0]]
        net["nodes"] += nodes
        net["connections"] += [
            {"source": a, "target": b, "weight": 1.0, "enabled": True}
            for a, b in itertools.pairwise(link)
        ]

    return change


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        (_set("version", 1.0), "version must be a whole number (the format version, 1), got 1.0"),
        (_set("version", True), "version must be a whole number (the format version, 1), got True"),
        (_set("network", "connections", {}), "network: connections must be a list, got dict"),
        (_set("network", "nodes", {}), "network: nodes must be a list, got dict"),
        (_chain(10_001), "10,004 nodes in network.nodes, more than the limit of 10,000"),
    ],
)
def test_an_arbitrator_file_no_run_writes_is_refused(tmp_path, capsys, change, needle):
    path = _arbitrator(tmp_path, change)
    with pytest.raises(ArbitratorError) as info:
        ArbitratorFile.load(path)
    assert str(info.value).startswith(f"{path}: ") and needle in str(info.value)
    err = one_line_error(capsys, "replay", "--arbitrator", path, "--maze", "obstacle", "--json")
    assert needle in err


def test_a_long_chain_within_the_limits_compiles_without_recursion(tmp_path, monkeypatch):
    import sys

    monkeypatch.setattr(sys, "getrecursionlimit", lambda: 100)  # nothing may lean on it
    tree = json.loads(Path(ARBITRATOR).read_text())
    _chain(9_000)(tree)
    spec = NetworkSpec.from_dict(tree["network"])
    net = spec.compile()
    assert len(net.node_slot) >= 9_001
    # The chain passes input 0 through identities: output 0 sees it (plus its own inputs).
    out = net.activate([0.0] * net.n_inputs)
    assert np.all(np.isfinite(out))


def test_a_cycle_in_a_feed_forward_network_names_a_node_on_it(tmp_path):
    def cycle(t):
        net = t["network"]
        net.pop("recurrent", None)
        a, b = net["outputs"]
        net["connections"] = [
            {"source": a, "target": b, "weight": 1.0, "enabled": True},
            {"source": b, "target": a, "weight": 1.0, "enabled": True},
        ]

    with pytest.raises(ArbitratorError, match=r"the network has a cycle \(through node 0\)"):
        ArbitratorFile.load(_arbitrator(tmp_path, cycle))


# -- checkpoints ----------------------------------------------------------------------------


def _rewrite_member(ckpt, name, data: bytes):
    """``ckpt`` with member ``name`` replaced by ``data`` (stored, not compressed)."""
    with zipfile.ZipFile(ckpt) as z:
        members = {i.filename: z.read(i) for i in z.infolist()}
    members[name] = data
    with zipfile.ZipFile(ckpt, "w") as z:
        for k, v in members.items():
            z.writestr(k, v)


def _npy_header(shape, dtype="<f8") -> bytes:
    buf = io.BytesIO()
    header = {"descr": dtype, "fortran_order": False, "shape": shape}
    np.lib.format.write_array_header_1_0(buf, header)
    return buf.getvalue()


def _no_inflating(monkeypatch):
    def refuse(*args, **kw):
        raise AssertionError("the arrays were inflated before their sizes were checked")

    monkeypatch.setattr("offline_evolution.checkpoint.np.load", refuse)


def test_a_zip_bomb_checkpoint_is_refused_before_it_is_inflated(
    tmp_path, monkeypatch, map_elites_checkpoint
):
    ckpt = map_elites_checkpoint
    n = (64 << 20) // 8  # 64 MiB of zeros: about 64 KB deflated
    with (
        zipfile.ZipFile(ckpt, "a", zipfile.ZIP_DEFLATED) as z,
        z.open("bomb.npy", "w", force_zip64=True) as f,
    ):
        f.write(_npy_header((n,)))
        for _ in range(8):
            f.write(bytes(8 << 20))
    assert ckpt.stat().st_size < 2 << 20
    monkeypatch.setenv("EVORBC_MAX_CHECKPOINT_BYTES", str(16 << 20))
    _no_inflating(monkeypatch)
    with pytest.raises(CheckpointError) as info:
        load_checkpoint(ckpt)
    message = str(info.value)
    assert message.startswith(f"{ckpt}: not a usable checkpoint (")
    assert "bytes of arrays once inflated, more than the limit of 16,777,216" in message
    assert "EVORBC_MAX_CHECKPOINT_BYTES=" in message


def test_an_array_whose_header_disagrees_with_its_size_is_refused(
    monkeypatch, map_elites_checkpoint
):
    _rewrite_member(map_elites_checkpoint, "solution.npy", _npy_header((10**6, 5)) + bytes(80))
    _no_inflating(monkeypatch)
    with pytest.raises(CheckpointError, match=r"solution.npy declares shape \(1000000, 5\)"):
        load_checkpoint(map_elites_checkpoint)


@pytest.mark.parametrize(
    ("header_change", "array_changes", "reason"),
    [
        (None, {"solution": lambda a: a + 0j}, "solution must hold real numbers (float), got comp"),
        (None, {"objective": lambda a: a.astype(np.int64)}, "objective must hold real numbers"),
    ],
)
def test_a_checkpoint_array_of_another_kind_is_refused(
    map_elites_checkpoint, header_change, array_changes, reason
):
    edited(map_elites_checkpoint, header_change, **array_changes)
    with pytest.raises(CheckpointError) as info:
        generate_repertoire(small_settings(), checkpoint=map_elites_checkpoint)
    message = str(info.value)
    assert message.startswith(f"{map_elites_checkpoint}: not a usable checkpoint (")
    assert reason in message


@pytest.mark.parametrize("version", [1.0, True, "1", 2])
def test_a_checkpoint_version_must_be_the_int_1(map_elites_checkpoint, version):
    header, _ = load_checkpoint(map_elites_checkpoint)
    assert header["version"] == 1  # written since the key exists
    edited(map_elites_checkpoint, {"version": version})
    with pytest.raises(CheckpointError, match="version"):
        load_checkpoint(map_elites_checkpoint)


def test_a_checkpoint_that_is_a_symlink_loop_is_one_line(tmp_path, capsys):
    loop = tmp_path / "ck.npz"
    os.symlink(loop.name, loop)
    argv = ["repertoire", *TINY, "--checkpoint", loop, "--out", tmp_path / "r.json"]
    err = one_line_error(capsys, *argv)
    assert str(loop) in err and "symbolic links" in err
    assert not (tmp_path / "r.json").exists()


def _genome_cycle(data):
    g = data["population"]["genomes"][0]
    out, other = g["nodes"][0]["key"], g["nodes"][1]["key"]
    g["connections"] += [
        {"key": [out, other], "innovation": 9001, "weight": 1.0, "enabled": True},
        {"key": [other, out], "innovation": 9002, "weight": 1.0, "enabled": False},
    ]


def _second_species(data):
    species = data["population"]["species"]
    twin = copy.deepcopy(species[0])
    twin["key"] = max(s["key"] for s in species) + 1
    species.append(twin)
    data["population"]["next_species_key"] = twin["key"] + 1


def _node_key_in_use(data):
    pop = data["population"]
    pop["next_node_key"] = max(n["key"] for g in pop["genomes"] for n in g["nodes"])


NEAT_CASES = {
    "empty-species": (_set("population", "species", []), "population.species is empty"),
    "next-genome-key": (_set("population", "next_genome_key", 1), "next_genome_key is 1, but"),
    "next-node-key": (_node_key_in_use, "population.next_node_key is"),
    "negative-elapsed": (_set("elapsed", -5.0), "elapsed must be 0 s or more, got -5.0"),
    "negative-hall": (_set("hall_of_fame", "size", -3), "hall_of_fame.size must be 1 or more"),
    "genome-cycle": (_genome_cycle, "population.genomes[0].connections: the network has a cycle"),
    "two-species": (_second_species, "is in more than one species"),
    "species-map": (
        _set("population", "genome_to_species", []),
        "genome_to_species disagrees with the species' members",
    ),
    "fitness-nan": (_set("population", "genomes", 0, "fitness", math.nan), "fitness must be"),
}


@pytest.mark.parametrize("case", NEAT_CASES)
def test_a_neat_population_that_does_not_add_up_is_refused(neat_checkpoint, small_repertoire, case):
    change, reason = NEAT_CASES[case]
    s, ckpt = neat_checkpoint
    data = json.loads(ckpt.read_text())
    change(data)
    ckpt.write_text(json.dumps(data))
    with pytest.raises(CheckpointError) as info:
        evolve(s, small_repertoire, checkpoint=ckpt)
    message = str(info.value)
    assert message.startswith(f"{ckpt}: not a usable checkpoint (") and reason in message
    assert "\n" not in message and ckpt.exists()


@pytest.mark.parametrize("version", [1.0, True])
def test_a_neat_checkpoint_version_must_be_an_int(neat_checkpoint, small_repertoire, version):
    s, ckpt = neat_checkpoint
    data = json.loads(ckpt.read_text())
    assert data["version"] == 1
    data["version"] = version
    ckpt.write_text(json.dumps(data))
    with pytest.raises(CheckpointError, match="version must be a whole number") as info:
        evolve(s, small_repertoire, checkpoint=ckpt)
    assert info.value.discardable  # recognisably a NEAT checkpoint: --restart may delete it
    assert checkpoint_kind(ckpt) == NEAT_KIND


def test_a_checkpoint_without_a_version_still_loads(map_elites_checkpoint):
    header, arrays = load_checkpoint(map_elites_checkpoint)
    del header["version"]
    import offline_evolution.checkpoint as checkpoint

    buf = io.BytesIO()
    np.savez(buf, __header__=np.array(json.dumps(header)), **arrays)
    map_elites_checkpoint.write_bytes(buf.getvalue())
    assert "version" not in load_checkpoint(map_elites_checkpoint)[0]
    assert checkpoint.VERSION == 1
    save_checkpoint(map_elites_checkpoint, header, arrays)


# -- the ask/tell loop refuses at tell what the file would refuse at the end ----------------


@pytest.mark.parametrize(
    ("quality", "heading", "needle"),
    [
        (5.0, 0.0, "quality must lie in [0, 1] for metric circular"),
        (-0.5, 0.0, "quality must lie in [0, 1] for metric circular"),
        (0.5, 1e6, "heading must be finite and within +-1000 rad"),
    ],
)
def test_tell_refuses_values_no_repertoire_file_may_hold(quality, heading, needle):
    from evorbc_ros.robots.primitive import ParameterSpec
    from offline_evolution.repertoire.map_elites import MapElites

    settings = small_settings()
    two = (ParameterSpec("a", "m/s", -1.0, 1.0), ParameterSpec("b", "rad/s", -2.0, 2.0))
    run = MapElites(settings, parameters=two, max_reach=0.5)
    genes = run.ask()
    n = len(genes)
    with pytest.raises(ValueError, match=re.escape(needle)):
        run.tell(genes, np.full(n, quality), 0.1 * genes, np.full(n, heading))
