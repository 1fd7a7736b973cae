"""A seeded corpus of broken and hostile input files, for every format evorbc reads.

Each :class:`Case` is a set of files and the command line that loads them, as a user would
run it. Two families:

* **named** cases: the hostile files a careless or malicious user makes (alias bombs,
  zip bombs, symlink loops, a repertoire whose primitives lie outside its archive, a
  checkpoint whose keys collide, ...). Each must be *refused*.
* **mutants**: a shipped or freshly made valid file, parsed and changed at random (a key
  dropped, a value of another type, a huge or negative number, a duplicated key, a
  truncated or flipped byte). Each may be accepted or refused, but must never hang,
  exhaust memory or end in an internal error.

Cases are made from a seed, so a failing case is made again by its name. ``big`` adds the
cases that need hundreds of megabytes (a 3 M-primitive repertoire, a 200,000-wall maze).
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import random
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

import evorbc_ros
from evorbc_ros.config import config_dir

DATA = Path(evorbc_ros.__file__).parent / "data"


@dataclass
class Case:
    """One input to load.

    Attributes:
        name: unique and stable (``family/kind/what``), to make the case again.
        kind: the format under test (``repertoire``, ``maze``, ...).
        files: file name -> bytes, or a callable that makes the file at a path
            (symlinks, FIFOs, big files written in pieces).
        argv: the command line; ``{dir}`` is the case's folder, ``{base}`` the folder of
            the valid base files.
        expect: ``"refused"`` for a named case, ``None`` for a mutant (either outcome).
        program: ``evorbc-evolve`` or ``evorbc-study``.
        env: environment variables set while it loads (a lowered limit).
        what: what a mutant changed.
    """

    name: str
    kind: str
    files: dict[str, bytes | Callable[[Path], None]]
    argv: list[str]
    expect: str | None = None
    program: str = "evorbc-evolve"
    env: dict[str, str] = field(default_factory=dict)
    what: str = ""


# -- the commands that load each format -------------------------------------------------------

#: A task short enough that an accepted controller's replay costs a fraction of a second.
SHORT_TASK = {
    "mazes": ["obstacle"],
    "episode_time": 1.0,
    "samples_per_maze": 1,
    "sensors": str(config_dir() / "sensors" / "4ws-p8m.yaml"),  # the shipped 4ws-5 controller's
}
#: A tiny MAP-Elites run, as tests/test_errors_checkpoints.py makes (80 evaluations).
TINY_REPERTOIRE = ["--initial-batch", "20", "--batch-size", "10", "--iterations", "6"]
#: A tiny NEAT run: the shipped settings with the smallest population they allow (5 species
#: of 2), one generation.
NEAT_POPULATION = 10

ARBITRATOR = str(DATA / "4ws-5.arbitrator.json")

COMMANDS = {
    "repertoire": ["export-csv", "{dir}/f.json", "--out", "{dir}/out.csv"],
    "arbitrator": [
        "replay", "--arbitrator", "{dir}/f.json", "--task", "{base}/task.yaml",
        "--maze", "obstacle", "--json",
    ],
    "maze": [
        "replay", "--arbitrator", ARBITRATOR, "--task", "{base}/task.yaml",
        "--maze", "{dir}/f.yaml", "--json",
    ],
    "task": ["replay", "--arbitrator", ARBITRATOR, "--task", "{dir}/f.yaml", "--json"],
    "sensors": ["replay", "--arbitrator", ARBITRATOR, "--task", "{dir}/task.yaml", "--json"],
    "repertoire-settings": [
        "repertoire", "--config", "{dir}/f.yaml", *TINY_REPERTOIRE, "--quiet",
        "--out", "{dir}/r.json",
    ],
    "neat": [
        "arbitrator", "--repertoire", "{base}/r.json", "--neat-config", "{dir}/f.ini",
        "--task", "{base}/task.yaml", "--generations", "1", "--quiet", "--out", "{dir}/a.json",
    ],
    "me-checkpoint": [
        "repertoire", "--robot", "4ws-5", *TINY_REPERTOIRE, "--quiet",
        "--checkpoint", "{dir}/f.npz", "--out", "{dir}/r.json",
    ],
    "neat-checkpoint": [
        "arbitrator", "--repertoire", "{base}/r.json", "--neat-config", "{base}/neat.ini",
        "--task", "{base}/task.yaml", "--seed", "1", "--generations", "2", "--quiet",
        "--checkpoint", "{dir}/f.json", "--out", "{dir}/a.json",
    ],
    "study": ["status", "{dir}/f.yaml", "--results", "{dir}/results"],
}  # fmt: skip

#: The file each kind's command reads, in the case's folder.
FILE = {
    "repertoire": "f.json",
    "arbitrator": "f.json",
    "maze": "f.yaml",
    "task": "f.yaml",
    "sensors": "sensors.yaml",
    "repertoire-settings": "f.yaml",
    "neat": "f.ini",
    "me-checkpoint": "f.npz",
    "neat-checkpoint": "f.json",
    "study": "f.yaml",
}


def make_bases(folder: Path) -> None:
    """Write the valid base files the commands and mutants start from into ``folder``.

    ``r.json`` (the shipped 4ws-5 repertoire), ``task.yaml`` (:data:`SHORT_TASK`),
    ``neat.ini`` (population :data:`NEAT_POPULATION`), ``me.npz`` (a MAP-Elites checkpoint
    of the tiny run, stopped early) and ``neat.json`` (a NEAT checkpoint after one
    generation of the ``neat-checkpoint`` command).
    """
    from offline_evolution.checkpoint import Interrupted
    from offline_evolution.cli import main
    from offline_evolution.repertoire.map_elites import generate_repertoire
    from offline_evolution.repertoire.settings import load_settings

    folder.mkdir(parents=True, exist_ok=True)
    (folder / "r.json").write_bytes((DATA / "4ws-5.repertoire.json").read_bytes())
    (folder / "task.yaml").write_text(yaml.safe_dump(SHORT_TASK))
    neat = (config_dir() / "neat" / "4ws.ini").read_text()
    (folder / "neat.ini").write_text(
        neat.replace("pop_size              = 150", f"pop_size = {NEAT_POPULATION}")
    )
    polls: list[int] = []
    with contextlib.suppress(Interrupted):
        generate_repertoire(
            load_settings(robot="4ws-5", initial_batch=20, batch_size=10, iterations=6),
            checkpoint=folder / "me.npz",
            should_stop=lambda: polls.append(1) or len(polls) > 3,
        )
    argv = [a.replace("{base}", str(folder)) for a in COMMANDS["neat-checkpoint"]]
    argv[argv.index("2")] = "1"
    argv[argv.index("{dir}/f.json")] = str(folder / "neat.json")
    argv[argv.index("{dir}/a.json")] = str(folder / "neat-a.json")
    code = main([*argv, "--keep-checkpoint"])
    if code != 0 or not (folder / "neat.json").exists():
        raise RuntimeError(f"could not make the NEAT checkpoint base (status {code})")


def base_text(kind: str, bases: Path) -> bytes:
    """The valid file a mutant of ``kind`` starts from."""
    source = {
        "repertoire": bases / "r.json",
        "arbitrator": Path(ARBITRATOR),
        "maze": config_dir() / "mazes" / "obstacle.yaml",
        "task": bases / "task.yaml",
        "sensors": config_dir() / "sensors" / "4ws-p8m.yaml",
        "repertoire-settings": config_dir() / "repertoire" / "4ws.yaml",
        "neat": bases / "neat.ini",
        "me-checkpoint": bases / "me.npz",
        "neat-checkpoint": bases / "neat.json",
        "study": config_dir() / "studies" / "bin-time.yaml",
    }[kind]
    return source.read_bytes()


def task_naming_sensors() -> bytes:
    """A short task whose sensors are the case's ``sensors.yaml``."""
    return yaml.safe_dump({**SHORT_TASK, "sensors": "{dir}/sensors.yaml"}).encode()


def case(name: str, kind: str, files: dict, expect: str | None = "refused", **kw) -> Case:
    """A :class:`Case` loading ``files`` with ``kind``'s command (``kw``: more fields)."""
    if kind == "sensors" and "task.yaml" not in files:
        files = {**files, "task.yaml": task_naming_sensors()}
    if kind == "study":
        kw.setdefault("program", "evorbc-study")
    return Case(name, kind, files, list(COMMANDS[kind]), expect, **kw)


# -- mutants ----------------------------------------------------------------------------------

#: Values a careless or hostile edit puts in a file.
HOSTILE_VALUES: list = [
    None, True, False, 0, -1, 1, 2**31, -(2**63), 10**30, 1e300, -1e300, 1e-300, 0.5,
    "", "0.9", "nan", "inf", "\u00e9\u00e8", [], {}, [1, 2], {"a": 1}, [[]], "x" * 1000,
]  # fmt: skip


def _paths(node, where=()) -> list[tuple]:
    """Every key path in a nested tree of dicts and lists."""
    out = [where]
    if isinstance(node, dict):
        for k, v in node.items():
            out += _paths(v, (*where, k))
    elif isinstance(node, list):
        # Long columns: a few entries stand for all.
        for i in sorted({0, 1, len(node) - 1} & set(range(len(node)))):
            out += _paths(node[i], (*where, i))
    return out


def _get(tree, path):
    for key in path:
        tree = tree[key]
    return tree


def mutate_tree(tree, rng: random.Random):
    """A copy of ``tree`` with one random structural or value change; (tree, description)."""
    tree = copy.deepcopy(tree)
    paths = [p for p in _paths(tree) if p]
    path = rng.choice(paths)
    parent, key = _get(tree, path[:-1]), path[-1]
    op = rng.choice(["value", "value", "value", "drop", "add", "double", "shrink", "swap"])
    where = ".".join(map(str, path))
    if op == "value":
        value = rng.choice(HOSTILE_VALUES)
        parent[key] = copy.deepcopy(value)
        return tree, f"{where} = {json.dumps(value)[:30]}"
    if op == "drop":
        del parent[key]
        return tree, f"{where} dropped"
    if op == "add":
        if isinstance(parent, dict):
            parent["unexpected_key"] = 1
        else:
            parent.append(copy.deepcopy(parent[key]))
        return tree, f"{where}: added an entry"
    if op == "double":
        value = parent[key]
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            parent[key] = value * rng.choice([-1, 1e6, 1e-12])
            return tree, f"{where} scaled"
        if isinstance(value, list) and value:
            parent[key] = value + value
            return tree, f"{where} doubled"
        parent[key] = [value]
        return tree, f"{where} wrapped in a list"
    if op == "shrink":
        value = parent[key]
        parent[key] = value[: len(value) // 2] if isinstance(value, (list, str)) else None
        return tree, f"{where} halved"
    other = rng.choice(paths)
    if other[: len(path)] != path and path[: len(other)] != other:
        a, b = _get(tree, other[:-1]), other[-1]
        parent[key], a[b] = copy.deepcopy(a[b]), copy.deepcopy(parent[key])
    return tree, f"{where} swapped with {'.'.join(map(str, other))}"


def mutate_bytes(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    """``data`` truncated, with a byte flipped, or with bytes inserted; (bytes, description)."""
    op = rng.choice(["truncate", "flip", "insert"])
    at = rng.randrange(max(len(data), 1))
    if op == "truncate":
        return data[:at], f"truncated at byte {at}"
    if op == "flip":
        return data[:at] + bytes([data[at] ^ (1 << rng.randrange(8))]) + data[at + 1 :], (
            f"bit flipped at byte {at}"
        )
    junk = rng.choice([b"\x00", b"\xff\xfe", b"\xef\xbb\xbf", b"{[", b"\n  - *a\n", b"\\ud800"])
    return data[:at] + junk + data[at:], f"{junk!r} inserted at byte {at}"


def _dump(kind: str, tree) -> bytes:
    if kind in ("repertoire", "arbitrator", "neat-checkpoint"):
        return json.dumps(tree).encode()
    return yaml.safe_dump(tree, sort_keys=False).encode()


def _load(kind: str, data: bytes):
    if kind in ("repertoire", "arbitrator", "neat-checkpoint"):
        return json.loads(data)
    return yaml.safe_load(data)


def _npz_mutant(data: bytes, rng: random.Random) -> tuple[bytes, str]:
    """A MAP-Elites checkpoint with one array or header value changed."""
    arrays = dict(np.load(io.BytesIO(data), allow_pickle=False))
    name = rng.choice(sorted(arrays))
    if name == "__header__":
        header = json.loads(str(arrays[name]))
        tree, what = mutate_tree(header, rng)
        arrays[name] = np.array(json.dumps(tree))
    else:
        a = arrays[name]
        op = rng.choice(["nan", "big", "shape", "dtype", "empty"])
        if op == "nan" and a.dtype.kind == "f" and a.size:
            a = a.copy()
            a.flat[rng.randrange(a.size)] = rng.choice([np.nan, np.inf, 1e300])
        elif op == "big" and a.size:
            a = a.astype(np.float64) * 1e6
        elif op == "shape":
            a = a.reshape(-1)[: max(a.size - 1, 0)]
        elif op == "dtype":
            a = a.astype(rng.choice([np.complex128, np.int8, np.bool_, "U3"]))
        else:
            a = a[:0]
        arrays[name] = a
        what = f"array {name}: {op}"
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue(), what


def _ini_mutant(text: str, rng: random.Random) -> tuple[bytes, str]:
    """NEAT settings with one value replaced by a hostile one, or a line dropped."""
    lines = text.splitlines()
    values = [i for i, line in enumerate(lines) if "=" in line and not line.startswith("#")]
    i = rng.choice(values)
    key = lines[i].split("=")[0].strip()
    if rng.random() < 0.2:
        del lines[i]
        return "\n".join(lines).encode(), f"{key} dropped"
    value = rng.choice(["", "-1", "0", "1e308", "10" * 20, "nan", "yes", "x", "5000", "1.5"])
    lines[i] = f"{key} = {value}"
    return "\n".join(lines).encode(), f"{key} = {value}"


def mutants(bases: Path, seed: int, per_kind: int) -> Iterator[Case]:
    """``per_kind`` mutants of each format, from ``seed``."""
    for kind in FILE:
        rng = random.Random(f"{seed}/{kind}")
        data = base_text(kind, bases)
        for i in range(per_kind):
            if kind == "me-checkpoint":
                text, what = _npz_mutant(data, rng)
            elif kind == "neat":
                text, what = _ini_mutant(data.decode(), rng)
            elif rng.random() < 0.25:
                text, what = mutate_bytes(data, rng)
            else:
                text, what = mutate_tree(_load(kind, data), rng)
                text = _dump(kind, text)
            yield case(f"mutant/{kind}/{seed}-{i}", kind, {FILE[kind]: text}, None, what=what)
