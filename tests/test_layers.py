"""Imports go one way and in no circle; the onboard package names no higher layer.

docs/design.md sections 17 and 19: ``evorbc_ros`` (onboard) is the lowest layer,
``sim_bridge`` (the simulation) sits on it and ``offline_evolution`` (the search) on
both. The import graph is read from the source (``ast``), function-level imports
included, since a lazy import is still a dependency: a new upward import or a new circle
fails here.
"""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: Package -> its folder, lowest layer first.
PACKAGES = {
    "evorbc_ros": ROOT / "evorbc_ros" / "evorbc_ros",
    "sim_bridge": ROOT / "sim_bridge" / "sim_bridge",
    "offline_evolution": ROOT / "offline_evolution",
}
#: Circles tolerated while they last, never required (none now: the study's results and
#: selection replays were one, broken by study/folder.py).
KNOWN_CYCLES: set[frozenset[str]] = set()


def modules() -> dict[str, tuple[Path, bool]]:
    """Every module of the three packages: dotted name -> (file, is a package)."""
    found = {}
    for folder in PACKAGES.values():
        for path in folder.rglob("*.py"):
            parts = list(path.relative_to(folder.parent).with_suffix("").parts)
            package = parts[-1] == "__init__"
            found[".".join(parts[:-1] if package else parts)] = (path, package)
    return found


def import_graph() -> dict[str, set[str]]:
    """Module -> the modules of the three packages it imports (anywhere in its code)."""
    mods = modules()
    graph = {}
    for name, (path, package) in mods.items():
        out = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                out |= {a.name for a in node.names if a.name in mods}
            elif isinstance(node, ast.ImportFrom):
                base = name.split(".") if package else name.split(".")[:-1]
                if node.level:
                    base = [*base[: len(base) - node.level + 1], node.module or ""]
                    module = ".".join(p for p in base if p)
                else:
                    module = node.module
                for alias in node.names:
                    # ``from pkg import sub`` depends on the submodule, else on ``pkg``.
                    sub = f"{module}.{alias.name}"
                    out |= {sub} if sub in mods else ({module} & mods.keys())
        graph[name] = out - {name}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[set[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = set()
            while not component or w != v:
                w = stack.pop()
                on.discard(w)
                component.add(w)
            if len(component) > 1:
                found.append(component)

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_module_imports_a_circle():
    found = [c for c in cycles(import_graph()) if frozenset(c) not in KNOWN_CYCLES]
    assert found == [], f"import cycles: {[sorted(c) for c in found]}"


def test_the_cycle_check_finds_a_circle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert cycles(graph) == [{"a", "b", "c"}]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_no_layer_imports_a_higher_one():
    layers = list(PACKAGES)
    upward = []
    for module, imports in import_graph().items():
        rank = layers.index(module.split(".")[0])
        upward += [f"{module} -> {m}" for m in imports if layers.index(m.split(".")[0]) > rank]
    assert upward == []


def test_the_onboard_package_names_no_higher_layer_not_even_in_a_string():
    """No import path, docstring, comment or data file of evorbc_ros names them: the
    simulation and the search register their adapters for a robot themselves."""
    named = []
    for path in sorted((ROOT / "evorbc_ros").rglob("*")):
        if path.is_file() and path.suffix in (".py", ".md", ".yaml", ".xml", ".cfg", ".txt"):
            text = path.read_text(encoding="utf-8")
            named += [
                f"{path.relative_to(ROOT)}: {w}"
                for w in PACKAGES
                if w != "evorbc_ros" and w in text
            ]
    assert named == []


def test_each_robot_family_has_its_one_folder_in_the_simulation():
    """docs/design.md section 19: each family's simulation code is ``sim_bridge/<family>/``,
    beside its onboard module ``evorbc_ros/robots/<family>.py``; its adapters point into it,
    and no module outside it is named after a family."""
    from sim_bridge.robots.adapters import BUILTIN

    sim = PACKAGES["sim_bridge"]
    onboard = PACKAGES["evorbc_ros"] / "robots"
    assert sorted(BUILTIN) == ["diff_drive", "four_ws", "hexapod", "legged"]
    for family, adapters in BUILTIN.items():
        assert (onboard / f"{family}.py").is_file(), family
        assert (sim / family / "__init__.py").is_file(), family
        paths = [adapters.simulation, adapters.bridge, adapters.design_check]
        outside = [p for p in paths if p and not p.startswith(f"sim_bridge.{family}.")]
        assert outside == [], family
    stray = [
        str(path.relative_to(sim))
        for path in sim.rglob("*.py")
        if path.parent.name not in BUILTIN and path.stem.startswith(tuple(BUILTIN))
    ]
    assert stray == []
