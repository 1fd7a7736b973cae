"""Package-level exports: a small public API, documented, and light to import."""

import importlib
import inspect
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGES = ("evorbc_ros", "offline_evolution", "sim_bridge")
HEAVY = ("numba", "pybullet", "ribs", "neat", "scipy", "matplotlib")


def loaded_after(code: str) -> list[str]:
    """The heavy libraries imported by running ``code`` in a fresh interpreter."""
    probe = (
        f"{code}\nimport json, sys\nprint(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def test_importing_evorbc_ros_and_all_its_names_stays_light():
    assert loaded_after("import evorbc_ros") == []
    assert loaded_after("from evorbc_ros import *") == []


def test_importing_the_other_packages_imports_no_simulation_or_search_library():
    assert loaded_after("import offline_evolution, sim_bridge") == []


@pytest.mark.parametrize("package", PACKAGES)
def test_every_exported_name_resolves_and_says_what_it_is(package):
    module = importlib.import_module(package)
    assert module.__all__ and set(module.__all__) <= set(dir(module))
    for name in module.__all__:
        value = getattr(module, name)
        if inspect.isclass(value) or inspect.isfunction(value):
            assert inspect.getdoc(value), f"{package}.{name} has no docstring"
        # Each name is described in the package's docstring, with its shapes and units.
        assert re.search(rf"\b{name}\b", module.__doc__), f"{package}.{name} not described"
    with pytest.raises(AttributeError, match=f"module '{package}' has no attribute 'nope'"):
        module.nope  # noqa: B018


def test_the_design_record_lists_the_public_api():
    text = Path(__file__).parents[1].joinpath("docs", "design.md").read_text()
    section = text.split("## 20.")[1].split("\n## ")[0]
    for package in PACKAGES:
        for name in importlib.import_module(package).__all__:
            assert f"`{name}`" in section, f"{package}.{name} missing from design.md section 20"
