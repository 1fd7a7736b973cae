"""Hostile and pathological YAML, JSON and maze files: each refused in one line naming the
file, quickly, without expanding anything (issue 39; docs/design.md section 12)."""

import json
import math
import resource
import subprocess
import sys

import numpy as np
import pytest
import yaml

from evorbc_ros import input_files, json_files, yaml_files
from evorbc_ros.config import ConfigError, config_dir, load_yaml_mapping
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.json_files import load_json_file, nesting_depth, parse_json
from evorbc_ros.repertoire import RepertoireError
from offline_evolution import cli
from sim_bridge.geometry import box_distances
from sim_bridge.maze import load_maze, maze_from_dict

GIB = 1 << 30
OBSTACLE = (config_dir() / "mazes" / "obstacle.yaml").read_text()


def laughs(levels: int = 9) -> str:
    """An alias bomb: ``levels`` levels of nine aliases, 9**levels strings once expanded."""
    return "\n".join(
        ["a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
        + [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, levels)]
    )


def refused(tmp_path, text: str, load=load_yaml_mapping) -> str:
    """The one-line ConfigError of loading ``text`` as a file; it must start with the path."""
    path = tmp_path / "f.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        load(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message, message
    return message.removeprefix(f"{path}: ")


def _limits():
    resource.setrlimit(resource.RLIMIT_AS, (2 * GIB, 2 * GIB))


def evolve_cli(*argv, timeout=60):
    """``evorbc-evolve ARGV`` in a subprocess limited to ``timeout`` s and 2 GiB."""
    return subprocess.run(
        [sys.executable, "-P", "-m", "offline_evolution.cli", *map(str, argv)],
        capture_output=True,
        text=True,
        timeout=timeout,
        preexec_fn=_limits,
        check=False,
    )


def one_error_line(result, path) -> str:
    assert result.returncode != 0
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and str(path) in lines[0] and "Traceback" not in result.stderr, lines
    return lines[0]


# -- YAML: anchors, aliases, merge keys ------------------------------------------------------

ALIASES = "line {}: YAML anchors and aliases are not accepted; write the values out"


@pytest.mark.parametrize(
    ("text", "line"),
    [
        # A small bomb (9**5 strings), so that the old loader accepts it quickly.
        (laughs(5) + "\n" + OBSTACLE, 1),
        (OBSTACLE.split("walls:")[0] + laughs(5) + "\nwalls: *a4\n", 7),  # after 6 lines
        ("x: &a [*a]\n" + OBSTACLE, 1),  # recursive
        ("x: &a {<<: *a, b: 1}\n" + OBSTACLE, 1),  # a merge-key cycle
        ("name: &n obstacle\nother: *n\n", 1),  # an anchor, used or not
        ("a: 1\nb: *n\n", 2),  # an alias without its anchor
    ],
)
def test_anchors_and_aliases_are_refused_where_they_start(tmp_path, text, line):
    assert refused(tmp_path, text) == ALIASES.format(line)


def test_a_merge_key_is_refused(tmp_path):
    message = refused(tmp_path, "a: 1\nb: {<<: {c: 1}, d: 2}\n")
    assert message == "line 2: YAML merge keys (<<) are not accepted; write the values out"


def test_a_full_alias_bomb_in_a_maze_is_refused_at_once_through_the_cli(tmp_path):
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text(OBSTACLE.split("walls:")[0] + laughs() + "\nwalls: *a8\n")
    result = evolve_cli("replay", "--arbitrator", default_arbitrator(), "--maze", bomb)
    assert "YAML anchors and aliases are not accepted" in one_error_line(result, bomb)


def test_an_arbitrator_whose_task_names_a_bomb_maze_is_refused(tmp_path):
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text(f"{laughs()}\nwalls: *a8\n")
    arbitrator = json.loads(default_arbitrator().read_text())
    arbitrator["evolution"]["task"]["mazes"] = [str(bomb)]
    path = tmp_path / "a.json"
    path.write_text(json.dumps(arbitrator))
    result = evolve_cli("replay", "--arbitrator", path, "--json")
    line = one_error_line(result, bomb)
    assert "line 1: YAML anchors and aliases are not accepted" in line


# -- YAML: duplicate keys and nesting --------------------------------------------------------


def test_a_duplicate_top_level_key_is_refused_with_both_lines(tmp_path):
    lines = OBSTACLE.count("\n")
    message = refused(tmp_path, OBSTACLE + "name: other\n", load_maze)
    first = OBSTACLE.splitlines().index("name: obstacle") + 1
    assert message == f"key 'name' appears twice (lines {first} and {lines + 1})"


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("a: 1\nb:\n  c: 1\n  d: 2\n  c: 3\n", "key 'c' appears twice (lines 3 and 5)"),
        ("a: [{x: 1, x: 2}]\n", "key 'x' appears twice (line 1)"),
        ("1: a\n0x1: b\n", "key 1 appears twice (lines 1 and 2)"),  # the same integer
    ],
)
def test_a_duplicate_nested_key_is_refused(tmp_path, text, expected):
    assert refused(tmp_path, text) == expected


@pytest.mark.parametrize("depth", [150, 5000, 100_000])
def test_deep_nesting_is_refused_at_the_limit_without_recursion(tmp_path, depth):
    message = refused(tmp_path, "x: " + "[" * depth + "]" * depth)
    assert message.startswith("line 1: nested too deeply: 101 levels of nesting, more than the")
    assert "EVORBC_MAX_NESTING" in message


def test_nesting_up_to_the_limit_loads(tmp_path):
    path = tmp_path / "f.yaml"
    path.write_text("x: " + "[" * 99 + "]" * 99)  # 100 levels with the top mapping
    data = load_yaml_mapping(path)["x"]
    for _ in range(98):
        (data,) = data
    assert data == []


def test_every_shipped_yaml_file_loads_as_before():
    files = sorted(config_dir().rglob("*.yaml"))
    assert len(files) > 20
    for path in files:
        assert load_yaml_mapping(path) == (yaml.safe_load(path.read_text()) or {}), path


# -- mazes -----------------------------------------------------------------------------------


def _maze(walls) -> dict:
    data = yaml.safe_load(OBSTACLE)
    data["walls"] = data["walls"] + walls
    return data


def test_a_maze_over_the_walls_limit_is_refused_from_the_count(tmp_path):
    walls = [[0.01 * i, -0.5, 0.01 * i, -0.4] for i in range(60_000)]
    message = refused(tmp_path, yaml.safe_dump(_maze(walls)), load_maze)
    assert message == (
        "60,026 walls in walls, more than the limit of 50,000; if that is intended, raise it "
        "with EVORBC_MAX_MAZE_WALLS=70000"
    )


def test_the_walls_limit_holds_for_a_maze_built_in_memory():
    walls = [[0.01 * i, -0.5, 0.01 * i, -0.4] for i in range(50_001)]
    with pytest.raises(ConfigError, match=r"^m\.yaml: 50,027 walls in walls, more than"):
        maze_from_dict(_maze(walls), "m.yaml")


def test_the_walls_limit_can_be_raised(tmp_path, monkeypatch):
    monkeypatch.setenv("EVORBC_MAX_MAZE_WALLS", "20")
    assert "more than the limit of 20;" in refused(tmp_path, OBSTACLE, load_maze)
    monkeypatch.setenv("EVORBC_MAX_MAZE_WALLS", "100")
    path = tmp_path / "f.yaml"
    assert len(load_maze(path).walls) == 26
    monkeypatch.setenv("EVORBC_MAX_MAZE_WALLS", "lots")
    assert refused(tmp_path, OBSTACLE, load_maze) == (
        "EVORBC_MAX_MAZE_WALLS must be a positive integer, got 'lots'"
    )


def test_a_maze_of_many_walls_inside_the_limit_loads(tmp_path):
    posts = [[-5.0 + 0.0001 * i, -0.55, -5.0 + 0.0001 * i, -0.5] for i in range(5000)]
    path = tmp_path / "f.yaml"
    path.write_text(yaml.safe_dump(_maze(posts)))
    assert len(load_maze(path).walls) == 5026


def test_every_shipped_maze_is_within_the_limit():
    for path in (config_dir() / "mazes").glob("*.yaml"):
        assert len(load_maze(path).walls) < 1000, path


def _brute_force_grid(maze, reach: float, cell: float):
    """``(offsets, ids)`` of a wall grid by testing every cell against every wall."""
    grid = maze.wall_grid(reach, cell)
    nx, ny = grid.shape
    cx = grid.origin[0] + (np.arange(nx) + 0.5) * cell
    cy = grid.origin[1] + (np.arange(ny) + 0.5) * cell
    gx, gy = (a.ravel() for a in np.meshgrid(cx, cy, indexing="ij"))
    limit = reach + cell * math.sqrt(0.5)
    near = np.stack([box_distances(gx, gy, b) <= limit for b in maze.boxes], axis=1)
    return np.concatenate([[0], np.cumsum(near.sum(axis=1))]), np.nonzero(near)[1]


@pytest.mark.parametrize(("reach", "cell"), [(1.1, 0.2), (0.5, 0.1), (3.05, 0.2)])
def test_the_wall_grid_is_the_one_testing_every_cell_against_every_wall_gives(reach, cell):
    posts = [[-5.0 + 0.005 * i, -0.55 + 0.0005 * i, -4.9 + 0.005 * i, -0.5] for i in range(2000)]
    for maze in (
        maze_from_dict(_maze(posts), "m"),
        load_maze(config_dir() / "mazes" / "gaps.yaml"),
    ):
        grid = maze.wall_grid(reach, cell)
        offsets, ids = _brute_force_grid(maze, reach, cell)
        assert np.array_equal(grid.offsets, offsets) and np.array_equal(grid.ids, ids)


def test_a_wide_maze_of_many_walls_replays_within_two_gib(tmp_path):
    # 2,000 walls along y = 400 m: a grid of 16 M cells. Testing every cell against every
    # wall took 286 s and 7.7 GB and failed; each wall now visits only the cells near it.
    walls = [[-400 + 0.4 * k, 400, -400 + 0.4 * k + 0.3, 400] for k in range(2000)]
    maze = tmp_path / "wide.yaml"
    maze.write_text(yaml.safe_dump(_maze(walls)))
    result = evolve_cli(
        "replay", "--arbitrator", default_arbitrator(), "--maze", maze, "--json", timeout=120
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert json.loads(result.stdout)


# -- JSON ------------------------------------------------------------------------------------

REPERTOIRE = default_repertoire()


def evolve(capsys, *argv) -> str:
    """``evorbc-evolve ARGV`` in this process: its one error line (it must fail)."""
    assert cli.main([str(a) for a in argv]) != 0
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


def json_refused(text: str, error=RepertoireError) -> str:
    with pytest.raises(error) as info:
        parse_json(text, "f.json", "repertoire", error)
    message = str(info.value)
    assert message.startswith("f.json: ") and "\n" not in message, message
    return message.removeprefix("f.json: ")


def test_a_duplicate_key_in_a_repertoire_is_refused_through_the_cli(tmp_path, capsys):
    path = tmp_path / "r.json"
    path.write_text('{"seed": 1, ' + REPERTOIRE.read_text().lstrip()[1:])
    line = evolve(capsys, "export-csv", path, "--out", tmp_path / "o.csv")
    assert line == f"evorbc-evolve: error: {path}: key 'seed' appears twice"


@pytest.mark.parametrize(
    ("text", "path"),
    [
        ('{"a": {"b": [1, {"c": 1, "d": 2, "c": 3}]}}', "a.b[1].c"),
        ('[{"x y": 1, "x y": 2}]', '[0]."x y"'),
        ('{"a": {}, "a": {}}', "a"),
    ],
)
def test_a_duplicate_nested_json_key_is_refused_with_its_path(text, path):
    assert json_refused(text) == f"key {path!r} appears twice"


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('{"a": ["ok", "\\ud800"]}', "a[1]: text with a lone surrogate ('\\ud800')"),
        ('{"a": {"\\udcff": 1}}', "a: a key with a lone surrogate ('\\udcff')"),
        ('"\\ude00x"', "the top level: text with a lone surrogate ('\\ude00x')"),
    ],
)
def test_a_lone_surrogate_is_refused_with_its_path(text, expected):
    message = json_refused(text)
    assert message.startswith(expected), message
    message.encode("ascii")  # printable anywhere


def test_a_lone_surrogate_in_a_repertoire_is_refused_through_the_cli(tmp_path, capsys):
    data = json.loads(REPERTOIRE.read_text())
    data["parameters"][0]["unit"] = "\ud800"
    path = tmp_path / "r.json"
    path.write_text(json.dumps(data))  # ensure_ascii: written as the escape \ud800
    line = evolve(capsys, "export-csv", path, "--out", tmp_path / "o.csv")
    assert line.startswith(f"evorbc-evolve: error: {path}: parameters[0].unit: text with a lone")


def test_surrogate_pairs_and_ordinary_text_load():
    assert parse_json('{"x": "\\ud83d\\ude00 caf\\u00e9"}', "f.json", "r", ValueError) == {
        "x": "\U0001f600 caf\u00e9"
    }


def test_json_nesting_is_bounded_by_the_limit(monkeypatch):
    assert nesting_depth(parse_json("[" * 100 + "]" * 100, "f.json", "r", ValueError)) == 100
    message = json_refused("[" * 101 + "]" * 101)
    assert message == (
        "corrupt repertoire file: 101 levels of nesting, more than the limit of 100; if that "
        "is intended, raise it with EVORBC_MAX_NESTING=200"
    )
    monkeypatch.setenv("EVORBC_MAX_NESTING", "200")
    parse_json("[" * 101 + "]" * 101, "f.json", "r", ValueError)


def test_nesting_depth_counts_lists_and_objects():
    assert [nesting_depth(v) for v in (1, "x", [], {}, [[1], [2, [3]]], {"a": {"b": [{}]}})] == [
        0,
        0,
        1,
        1,
        3,
        4,
    ]


def test_the_shipped_repertoires_and_arbitrators_parse_as_before():
    files = sorted(REPERTOIRE.parent.glob("*.json"))
    assert len(files) >= 4
    for path in files:
        text = path.read_text()
        assert parse_json(text, str(path), "file", ValueError) == json.loads(text), path


# -- files -----------------------------------------------------------------------------------


def test_a_symlink_loop_is_refused_in_one_line(tmp_path, capsys):
    loop = tmp_path / "loop"
    loop.symlink_to(tmp_path / "other")
    (tmp_path / "other").symlink_to(loop)
    line = evolve(capsys, "export-csv", loop, "--out", tmp_path / "o.csv")
    assert line == f"evorbc-evolve: error: {loop}: cannot read (Too many levels of symbolic links)"


def test_a_path_through_a_file_is_refused_in_one_line(tmp_path, capsys):
    (tmp_path / "r.json").write_text("{}")
    path = tmp_path / "r.json" / "x"
    line = evolve(capsys, "export-csv", path, "--out", tmp_path / "o.csv")
    assert line == f"evorbc-evolve: error: {path}: cannot read (Not a directory)"


def test_a_name_too_long_is_refused_in_one_line(tmp_path, capsys):
    path = tmp_path / ("r" * 300)
    line = evolve(capsys, "export-csv", path, "--out", tmp_path / "o.csv")
    assert line == f"evorbc-evolve: error: {path}: cannot read (File name too long)"


def test_a_maze_name_too_long_is_an_unknown_maze(capsys):
    line = evolve(capsys, "replay", "--arbitrator", default_arbitrator(), "--maze", "m" * 300)
    assert line.startswith(f"evorbc-evolve: error: unknown maze '{'m' * 300}'; shipped mazes: ")


def test_undecodable_text_is_refused_naming_the_byte(tmp_path, capsys):
    path = tmp_path / "r.json"
    path.write_bytes(b'{"robot": "caf\xe9"}')
    line = evolve(capsys, "export-csv", path, "--out", tmp_path / "o.csv")
    assert line == (
        f"evorbc-evolve: error: {path}: not a repertoire file (not UTF-8 text: byte 14 is 0xe9)"
    )


def test_a_small_file_is_read_without_a_buffer_of_the_formats_limit(tmp_path):
    # 2 GiB of address space: reading a repertoire asked for a 2 GiB buffer whatever its size.
    result = evolve_cli("export-csv", REPERTOIRE, "--out", tmp_path / "o.csv")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "o.csv").read_text().count("\n") > 100


@pytest.mark.parametrize("where", ["read", "decode", "parse"])
def test_memory_errors_while_loading_json_are_one_line(tmp_path, monkeypatch, where):
    path = tmp_path / "r.json"
    path.write_text("[1]")

    def no_memory(*args, **kwargs):
        raise MemoryError

    if where == "read":
        monkeypatch.setattr(input_files, "_read_at_most", no_memory)
    elif where == "decode":
        monkeypatch.setattr(input_files, "read_regular", lambda *a: _Undecodable())
    else:
        monkeypatch.setattr(json_files.json, "loads", no_memory)
    with pytest.raises(RepertoireError) as info:
        load_json_file(path, "repertoire", RepertoireError)
    message = str(info.value)
    assert message.startswith(f"{path}: cannot ") and "memory" in message, message


def test_a_memory_error_while_parsing_yaml_is_one_line(tmp_path, monkeypatch):
    def no_memory(self):
        raise MemoryError

    monkeypatch.setattr(yaml_files._StrictLoader, "get_single_data", no_memory)
    assert refused(tmp_path, OBSTACLE) == "cannot parse: the file does not fit in memory"


class _Undecodable(bytes):
    """Bytes whose decoding runs out of memory."""

    def decode(self, *args):
        raise MemoryError
