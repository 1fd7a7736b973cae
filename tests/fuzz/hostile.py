"""The named hostile and careless files of the corpus: each one must be refused.

Every case is one a user met or could make (issue 39's fault injection, and more): YAML
alias bombs, recursive aliases and merge keys, duplicate keys, zip bombs, symlink loops,
lone surrogates, files over a format's limits, and files whose syntax is fine but whose
meaning is not (primitives outside the archive, two in a cell, a quality its metric cannot
give, a checkpoint whose keys collide).
"""

from __future__ import annotations

import copy
import io
import itertools
import json
import os
import stat
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import yaml

from evorbc_ros.config import config_dir
from fuzz.corpus import ARBITRATOR, COMMANDS, SHORT_TASK, Case, base_text, case

MIB = 1 << 20


def _json(tree) -> bytes:
    return json.dumps(tree).encode()


def _yaml(tree) -> bytes:
    return yaml.safe_dump(tree, sort_keys=False).encode()


# -- YAML ---------------------------------------------------------------------------------------

#: Nine levels of nine: 9**9 (387 M) strings from a few hundred bytes.
LAUGHS = "\n".join(
    ["a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    + [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]
)


def maze_text(walls) -> str:
    return yaml.safe_dump({"name": "m", "wall_thickness": 0.01, "walls": walls, **START})


#: A start and target as the shipped obstacle maze has them (maze frame, m).
START = yaml.safe_load(base_text("maze", Path()).decode())
START = {k: v for k, v in START.items() if k not in ("name", "walls", "wall_thickness")}


def yaml_cases() -> Iterator[Case]:
    obstacle = base_text("maze", Path()).decode()
    yield case("named/maze/laughs-extra-key", "maze", {"f.yaml": f"{LAUGHS}\n{obstacle}"})
    walls_bomb = obstacle.split("walls:")[0] + LAUGHS + "\nwalls: *a8\n"
    walls_bomb += "\n".join(f"{k}: {json.dumps(v)}" for k, v in START.items())
    yield case("named/maze/laughs-as-walls", "maze", {"f.yaml": walls_bomb})
    yield case(
        "named/task/laughs-extra-key",
        "task",
        {"f.yaml": f"{LAUGHS}\n{yaml.safe_dump(SHORT_TASK)}"},
    )
    yield case("named/maze/recursive-alias", "maze", {"f.yaml": f"x: &a [*a]\n{obstacle}"})
    yield case(
        "named/maze/recursive-merge-key",
        "maze",
        {"f.yaml": f"x: &a {{<<: *a, b: 1}}\n{obstacle}"},
    )
    yield case(
        "named/maze/merge-key",
        "maze",
        {"f.yaml": f"base: &b {{wall_thickness: 0.01}}\nextra: {{<<: *b}}\n{obstacle}"},
    )
    yield case("named/maze/duplicate-key", "maze", {"f.yaml": f"{obstacle}\nname: other\n"})
    yield case(
        "named/task/duplicate-key",
        "task",
        {"f.yaml": yaml.safe_dump(SHORT_TASK) + "episode_time: 90.0\n"},
    )
    yield case("named/maze/deep-nesting", "maze", {"f.yaml": "x: " + "[" * 5000 + "]" * 5000})
    yield case("named/maze/latin-1", "maze", {"f.yaml": obstacle.encode() + b"# caf\xe9\n"})
    yield case("named/maze/nul-bytes", "maze", {"f.yaml": b"\x00" * 100})
    yield case(
        "named/task/hexapod-sensors-in-4ws-task",
        "task",
        {"f.yaml": _yaml({**SHORT_TASK, "sensors": str(config_dir() / "sensors/hexapod.yaml")})},
    )
    yield case(
        "named/task/episode-time-1e300",
        "task",
        {"f.yaml": _yaml({**SHORT_TASK, "episode_time": 1e300})},
    )
    yield case(
        "named/sensors/laughs",
        "sensors",
        {"sensors.yaml": f"{LAUGHS}\n" + base_text("sensors", Path()).decode()},
    )
    study = base_text("study", Path()).decode()
    yield case(
        "named/study/seeds-10-12",
        "study",
        {"f.yaml": study.replace("seeds: 30", "seeds: 1000000000000")},
    )
    yield case("named/study/laughs", "study", {"f.yaml": f"{LAUGHS}\n{study}"})


def maze_size_cases(big: bool) -> Iterator[Case]:
    # Over the walls limit (50,000): refused from the count, before any geometry.
    n = 200_000 if big else 60_000
    walls = [[0.01 * i, -0.5, 0.01 * i, -0.4] for i in range(n)]
    yield case(f"named/maze/{n}-walls", "maze", {"f.yaml": maze_text(walls)})
    # Within every limit, and so accepted: walls spread along y = 400 m make a wall grid of
    # 16 M cells (0.2 m), which took 286 s and 7.7 GB when each cell was tested against
    # each wall (docs/design.md section 12).
    n = 2000 if big else 500
    wide = [[-400 + 0.4 * k, 400, -400 + 0.4 * k + 0.3, 400] for k in range(n)]
    tree = yaml.safe_load(base_text("maze", Path()).decode())
    tree["walls"] += wide  # the obstacle maze, whose start lies within its own walls
    yield case(f"named/maze/wide-{n}-walls", "maze", {"f.yaml": _yaml(tree)}, "accepted")


# -- repertoires ---------------------------------------------------------------------------------


def repertoire_cases(bases: Path, big: bool) -> Iterator[Case]:
    base = json.loads(base_text("repertoire", bases))
    prim = base["primitives"]
    arch = base["archive"]

    def edited(name, change) -> Case:
        tree = copy.deepcopy(base)
        change(tree)
        return case(f"named/repertoire/{name}", "repertoire", {"f.json": _json(tree)})

    def set_behaviours(t, f):
        t["primitives"]["behaviour"] = [f(b) for b in t["primitives"]["behaviour"]]

    yield edited("all-outside-archive", lambda t: set_behaviours(t, lambda b: [b[0] + 10, b[1]]))
    just_out = arch["high"][0] + 1e-6

    def one_outside(t):
        t["primitives"]["behaviour"][0] = [just_out, t["primitives"]["behaviour"][0][1]]

    yield edited("one-just-outside", one_outside)

    def two_in_a_cell(t):
        p = t["primitives"]
        for key in ("genes", "behaviour", "heading", "quality"):
            p[key].append(copy.deepcopy(p[key][0]))
        t["summary"]["count"] += 1

    yield edited("two-in-one-cell", two_in_a_cell)
    yield edited("quality-5-circular", lambda t: t["primitives"]["quality"].__setitem__(0, 5.0))
    yield edited("quality-negative", lambda t: t["primitives"]["quality"].__setitem__(0, -0.5))
    yield edited("heading-1e6", lambda t: t["primitives"]["heading"].__setitem__(0, 1e6))
    yield edited("bin-size-1e-300", lambda t: t.__setitem__("bin_size", 1e-300))
    yield edited("eval-time-1e300", lambda t: t.__setitem__("eval_time", 1e300))
    strings = [str(q) for q in prim["quality"]]
    yield edited("quality-strings", lambda t: t["primitives"].__setitem__("quality", strings))
    yield edited(
        "quality-booleans",
        lambda t: t["primitives"].__setitem__("quality", [True] * len(prim["quality"])),
    )
    yield edited("genes-strings", lambda t: t["primitives"]["genes"][0].__setitem__(0, "0.5"))
    yield edited("dims-inconsistent", lambda t: t["archive"].__setitem__("dims", [40, 40]))
    yield edited("version-float", lambda t: t.__setitem__("version", 1.0))
    yield edited("version-true", lambda t: t.__setitem__("version", True))
    yield edited("surrogate-unit", lambda t: t["parameters"][0].__setitem__("unit", "\ud800"))
    text = _json(base).decode()
    yield case(
        "named/repertoire/duplicate-key",
        "repertoire",
        {"f.json": ('{"seed": 3, ' + text[1:]).encode()},
    )
    yield case(
        "named/repertoire/deep-nesting",
        "repertoire",
        {"f.json": ("[" * 100_000 + "]" * 100_000).encode()},
    )
    # Over the primitives limit, from the column lengths alone. Fast: a lowered limit;
    # big: 3 M primitives (400 MB) under the default one.
    n, env = (3_000_000, {}) if big else (2_000, {"EVORBC_MAX_PRIMITIVES": "1000"})

    def write_many(path: Path, n=n) -> None:
        tree = copy.deepcopy(base)
        del tree["primitives"]
        head = json.dumps(tree)[:-1]
        with open(path, "w") as f:
            f.write(head + ', "primitives": {')
            for i, key in enumerate(("genes", "behaviour", "heading", "quality")):
                f.write(f'{", " if i else ""}"{key}": [')
                item = json.dumps(prim[key][0])
                f.write(", ".join([item] * n))
                f.write("]")
            f.write("}}")

    yield case(f"named/repertoire/{n}-primitives", "repertoire", {"f.json": write_many}, env=env)


# -- arbitrators ------------------------------------------------------------------------------


def arbitrator_cases() -> Iterator[Case]:
    base = json.loads(Path(ARBITRATOR).read_bytes())

    def edited(name, change, **kw) -> Case:
        tree = copy.deepcopy(base)
        change(tree)
        return case(f"named/arbitrator/{name}", "arbitrator", {"f.json": _json(tree)}, **kw)

    yield edited("version-1e0", lambda t: t.__setitem__("version", 1.0))
    yield edited("version-true", lambda t: t.__setitem__("version", True))
    yield edited("connections-object", lambda t: t["network"].__setitem__("connections", {}))
    yield edited("bias-string", lambda t: t["network"]["nodes"][0].__setitem__("bias", "0.5"))

    def chain(t, n=100_000):
        net = t["network"]
        first = 1000
        nodes = [
            {"key": first + i, "bias": 0.0, "response": 1.0, "activation": "sigmoid",
             "aggregation": "sum"}
            for i in range(n)
        ]  # fmt: skip
        link = [net["inputs"][0], *range(first, first + n), net["outputs"][0]]
        conns = [
            {"source": a, "target": b, "weight": 1.0, "enabled": True}
            for a, b in itertools.pairwise(link)
        ]
        net["nodes"] += nodes
        net["connections"] += conns

    yield edited("100000-node-chain", chain)

    def cycle(t):
        net = t["network"]
        a, b = net["outputs"][0], net["outputs"][1]
        net.pop("recurrent", None)  # the base network is recurrent, where cycles are fine
        net["connections"] += [
            {"source": a, "target": b, "weight": 1.0, "enabled": True},
            {"source": b, "target": a, "weight": 1.0, "enabled": True},
        ]

    yield edited("cycle-feed-forward", cycle)

    def bomb_task(t):
        t["evolution"]["task"]["mazes"] = ["{dir}/bomb.yaml"]

    tree = copy.deepcopy(base)
    bomb_task(tree)
    argv = ["replay", "--arbitrator", "{dir}/f.json", "--json"]
    c = case(
        "named/arbitrator/task-names-a-bomb-maze",
        "arbitrator",
        {"f.json": _json(tree), "bomb.yaml": f"{LAUGHS}\nwalls: *a8\n".encode()},
    )
    c.argv = argv
    yield c
    yield edited("surrogate-input-name", lambda t: t["inputs"].__setitem__(0, "\udcff"))
    text = _json(base).decode()
    yield case(
        "named/arbitrator/duplicate-key",
        "arbitrator",
        {"f.json": ('{"kind": "standard", ' + text[1:]).encode()},
    )


# -- checkpoints ----------------------------------------------------------------------------------


def _npz(arrays: dict) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def npz_bomb(path: Path, gib: float, arrays: dict) -> None:
    """The checkpoint ``arrays`` with a ``solution`` that inflates to ``gib`` GiB of zeros."""
    header = np.lib.format.header_data_from_array_1_0(np.zeros(0))
    n = int(gib * (1 << 30)) // 8
    header["shape"] = (n,)
    head = io.BytesIO()
    np.lib.format.write_array_header_1_0(head, header)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=1) as z:
        for name, a in arrays.items():
            if name != "solution":
                z.writestr(f"{name}.npy", _npy(a))
        with z.open("solution.npy", "w", force_zip64=True) as f:
            f.write(head.getvalue())
            chunk = bytes(64 * MIB)
            left = n * 8
            while left:
                f.write(chunk[: min(left, len(chunk))])
                left -= min(left, len(chunk))


def _npy(a: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, a)
    return buf.getvalue()


def checkpoint_cases(bases: Path, big: bool) -> Iterator[Case]:
    me = dict(np.load(io.BytesIO(base_text("me-checkpoint", bases)), allow_pickle=False))

    def me_edited(name, change) -> Case:
        arrays = copy.deepcopy(me)
        change(arrays)
        return case(f"named/me-checkpoint/{name}", "me-checkpoint", {"f.npz": _npz(arrays)})

    yield me_edited("complex-solution", lambda a: a.__setitem__("solution", a["solution"] + 0j))
    yield me_edited(
        "string-solution", lambda a: a.__setitem__("solution", a["solution"].astype("U8"))
    )
    gib = 16 if big else 0.5
    yield case(
        f"named/me-checkpoint/zip-bomb-{gib}-gib",
        "me-checkpoint",
        {"f.npz": lambda p: npz_bomb(p, gib, me)},
        env={} if big else {"EVORBC_MAX_CHECKPOINT_BYTES": str(64 * MIB)},
    )
    yield case(
        "named/me-checkpoint/symlink-loop",
        "me-checkpoint",
        {"f.npz": lambda p: os.symlink(p.name, p)},
    )
    yield case(
        "named/me-checkpoint/not-a-zip",
        "me-checkpoint",
        {"f.npz": zlib.compress(b"\x00" * 1000)},
    )

    neat = json.loads(base_text("neat-checkpoint", bases))

    def neat_edited(name, change) -> Case:
        tree = copy.deepcopy(neat)
        change(tree)
        return case(f"named/neat-checkpoint/{name}", "neat-checkpoint", {"f.json": _json(tree)})

    yield neat_edited("empty-species", lambda t: t["population"].__setitem__("species", []))
    yield neat_edited(
        "colliding-next-genome-key",
        lambda t: t["population"].__setitem__("next_genome_key", 1),
    )
    yield neat_edited("negative-elapsed", lambda t: t.__setitem__("elapsed", -5.0))
    yield neat_edited("negative-hall-of-fame", lambda t: t["hall_of_fame"].__setitem__("size", -3))

    def genome_cycle(t):
        g = t["population"]["genomes"][0]
        out = g["nodes"][0]["key"]
        other = g["nodes"][1]["key"]
        g["connections"] += [
            {"key": [out, other], "innovation": 9001, "weight": 1.0, "enabled": True},
            {"key": [other, out], "innovation": 9002, "weight": 1.0, "enabled": True},
        ]

    yield neat_edited("genome-cycle-feed-forward", genome_cycle)
    yield neat_edited("version-float", lambda t: t.__setitem__("version", 1.0))
    yield case(
        "named/neat-checkpoint/symlink-loop",
        "neat-checkpoint",
        {"f.json": lambda p: os.symlink(p.name, p)},
    )


def neat_cases(bases: Path) -> Iterator[Case]:
    ini = base_text("neat", bases).decode()
    yield case(
        "named/neat/num-hidden-5000",
        "neat",
        {"f.ini": ini.replace("num_hidden            = 0", "num_hidden = 5000").encode()},
    )
    yield case(
        "named/neat/pop-size-10-9",
        "neat",
        {"f.ini": ini.replace("pop_size = 10", "pop_size = 1000000000").encode()},
    )


def not_files_cases() -> Iterator[Case]:
    """Paths that are not regular files, or files no format could be."""
    for kind in ("maze", "repertoire", "neat-checkpoint"):
        name = {"maze": "f.yaml", "repertoire": "f.json", "neat-checkpoint": "f.json"}[kind]
        yield case(f"named/{kind}/empty-file", kind, {name: b""})
        yield case(f"named/{kind}/a-folder", kind, {name: lambda p: p.mkdir()})
        yield case(f"named/{kind}/a-fifo", kind, {name: lambda p: os.mkfifo(p)})
        # A copy of /dev/zero (character device 1, 5): it never ends.
        yield case(
            f"named/{kind}/endless-device",
            kind,
            {name: lambda p: os.mknod(p, 0o600 | stat.S_IFCHR, os.makedev(1, 5))},
        )
        # A checkpoint that does not exist yet is a fresh start: either outcome is right.
        fresh = None if kind == "neat-checkpoint" else "refused"
        yield case(
            f"named/{kind}/dangling-symlink", kind, {name: lambda p: os.symlink("gone", p)}, fresh
        )
    yield case("named/maze/17-mib-of-comments", "maze", {"f.yaml": b"#" * (17 * MIB)})


def named(bases: Path, big: bool = False) -> Iterator[Case]:
    """Every named case; ``big`` makes the ones of hundreds of megabytes at full size."""
    yield from yaml_cases()
    yield from maze_size_cases(big)
    yield from repertoire_cases(bases, big)
    yield from arbitrator_cases()
    yield from checkpoint_cases(bases, big)
    yield from neat_cases(bases)
    yield from not_files_cases()
    assert set(COMMANDS)  # every kind has a command (corpus.COMMANDS)
