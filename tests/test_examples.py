"""The examples in docs/examples run and do what they say."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).parents[1] / "docs" / "examples"


def run_example(name: str, *args) -> str:
    cmd = [sys.executable, str(EXAMPLES / name), *map(str, args)]
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    return out.stdout


@pytest.mark.slow
def test_own_evaluation_evolves_saves_and_drives_a_unicycle_with_its_repertoire(tmp_path):
    first = tmp_path / "a.json"
    lines = run_example("own_evaluation.py", "--out", first, "--seed", 2).splitlines()
    assert lines[0].startswith("unicycle repertoire: ") and "22000 evaluations" in lines[0]
    assert len(lines) == 4 and all("reached in" in line for line in lines[1:])
    data = json.loads(first.read_text())
    assert data["robot"] == "unicycle" and data["metric"] == "distance"
    assert [p["name"] for p in data["parameters"]] == ["speed", "turn_rate"]
    assert data["summary"]["count"] > 300 and data["summary"]["mean_quality"] > 0.8
    # The archive reaches no further than the top speed times T (0.3 m/s x 2 s).
    assert max(abs(v) for xy in data["primitives"]["behaviour"] for v in xy) <= 0.6
    again = tmp_path / "b.json"
    run_example("own_evaluation.py", "--out", again, "--seed", 2)
    assert again.read_bytes() == first.read_bytes()  # seeded
