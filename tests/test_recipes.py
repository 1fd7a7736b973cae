"""Recipes (config/recipes/, ``evorbc-evolve recipe``): each shipped recipe runs at the
small budget, an interrupted run resumes to the same files, bad recipes are refused in one
line, and the hashes the recipes state are the shipped files'."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from evorbc_ros.adaptation.settled import load_settled
from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import config_dir
from evorbc_ros.repertoire import Repertoire
from offline_evolution.cli import main
from offline_evolution.recipes.digest import Verdict, content_sha256, file_sha256
from offline_evolution.recipes.spec import load_recipe

ROOT = Path(__file__).resolve().parents[1]
RECIPES = sorted((ROOT / "config" / "recipes").glob("*.yaml"))
#: Recipes of measurements (docs/adaptation.md's upper bound): run like the others, their
#: outputs not shipped.
MEASUREMENTS = sorted((ROOT / "config" / "recipes" / "measurements").glob("*.yaml"))
SHIPPED = ROOT / "evorbc_ros" / "evorbc_ros" / "data"


def test_a_recipe_for_each_shipped_controller():
    made = {s.out for r in RECIPES for s in load_recipe(r).steps}
    assert {p.name for p in SHIPPED.glob("*.json")} <= made


@pytest.mark.parametrize("recipe", RECIPES, ids=lambda p: p.stem)
def test_stated_hashes_are_the_shipped_files(recipe):
    shipped = {file_sha256(p): p for p in SHIPPED.glob("*.json")}
    for step in load_recipe(recipe).steps:
        assert step.sha256 in shipped, step.step
        assert content_sha256(shipped[step.sha256]) == step.content_sha256
        if step.out in {p.name for p in shipped.values()}:
            assert shipped[step.sha256].name == step.out


@pytest.mark.parametrize("recipe", RECIPES + MEASUREMENTS, ids=lambda p: p.stem)
def test_each_recipe_runs_at_the_small_budget(recipe, tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["recipe", str(recipe), "--budget", "small", "--out", str(out), "--workers", "1"]
    assert main([*argv, "--quiet"]) == 0
    spec = load_recipe(recipe)
    for step in spec.steps:
        path = out / step.out
        if step.run == "arbitrator":
            arb = ArbitratorFile.load(path)
            # The names the shipped files record: the recipe reproduces them.
            repertoire = (
                spec.step(step.repertoire).out
                if step.repertoire
                else Path(step.repertoire_file).name
            )
            assert arb.repertoire["file"] == repertoire
            assert arb.evolution["generations"] == 2
            if step.init_from:
                assert arb.evolution["initial_network"]["file"] == spec.step(step.init_from).out
            if step.init_from_file:
                assert arb.evolution["initial_network"]["file"] == Path(step.init_from_file).name
        elif step.run == "settled":
            source = step.repertoire_file or out / spec.step(step.repertoire).out
            assert load_settled(path, Repertoire.load(source)).shape[1] == 3
        else:
            assert len(Repertoire.load(path)) > 0
    # Run again: every step is found finished and skipped.
    capsys.readouterr()
    assert main([*argv, "--quiet"]) == 0
    err = capsys.readouterr().err
    assert err.count("done before, skipped") == len(spec.steps)


def _tiny_recipe(folder: Path) -> Path:
    """A recipe of its own settings files (beside it), small enough for a test."""
    rep = yaml.safe_load((config_dir() / "repertoire" / "4ws.yaml").read_text())
    rep.update(initial_batch=400, batch_size=100, iterations=5)
    (folder / "rep.yaml").write_text(yaml.safe_dump(rep))
    neat = (config_dir() / "neat" / "4ws.ini").read_text()
    (folder / "neat.ini").write_text(neat.replace("pop_size              = 150", "pop_size = 24"))
    task = {"mazes": ["obstacle", "gaps"], "episode_time": 15.0, "sensors": "sensors/4ws.yaml"}
    (folder / "task.yaml").write_text(yaml.safe_dump(task))
    run = {"generations": 40, "checkpoint_every": 1, "hall_of_fame": 3, "post_samples": 1}
    run.update(neat=str(folder / "neat.ini"), task=str(folder / "task.yaml"))
    (folder / "run.yaml").write_text(yaml.safe_dump(run))
    steps = [
        {"step": "rep", "run": "repertoire", "robot": "4ws-5", "settings": "rep.yaml",
         "seed": 3, "out": "rep.json"},
        {"step": "arb", "run": "arbitrator", "repertoire": "rep", "settings": "run.yaml",
         "seed": 5, "out": "arb.json"},
    ]  # fmt: skip
    path = folder / "tiny.yaml"
    path.write_text(yaml.safe_dump({"recipe": "a test", "steps": steps}))
    return path


def test_an_interrupted_run_resumes_to_the_same_files(tmp_path, capsys):
    recipe = _tiny_recipe(tmp_path)
    whole, broken = tmp_path / "whole", tmp_path / "broken"
    assert main(["recipe", str(recipe), "--out", str(whole), "--quiet"]) == 0
    # Killed outright once the arbitrator step has checkpointed a generation.
    checkpoint = broken / "arb.json.checkpoint.json"
    cmd = [sys.executable, "-P", "-m", "offline_evolution.cli", "recipe", str(recipe)]
    proc = subprocess.Popen([*cmd, "--out", str(broken), "--quiet"], stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while not checkpoint.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate()
    assert checkpoint.exists() and not (broken / "arb.json").exists()
    capsys.readouterr()
    assert main(["recipe", str(recipe), "--out", str(broken), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert "rep (repertoire)" in err and "done before, skipped" in err
    assert "resuming from the checkpoint" in err
    assert (whole / "rep.json").read_bytes() == (broken / "rep.json").read_bytes()
    # The same file but for the wall-clock times it records.
    assert content_sha256(whole / "arb.json") == content_sha256(broken / "arb.json")
    assert not checkpoint.exists()


def test_a_folder_holds_one_recipe_and_budget(tmp_path, capsys):
    recipe = _tiny_recipe(tmp_path)
    out = tmp_path / "out"
    (out).mkdir()
    (out / "recipe-run.json").write_text(json.dumps({"recipe": {"recipe": "x"}, "budget": "small"}))
    assert main(["recipe", str(recipe), "--out", str(out)]) == 1
    err = capsys.readouterr().err.strip()
    assert err == (
        f"evorbc-evolve: error: {out} holds 'x' at the small budget, not this recipe at the "
        "full budget; choose another --out"
    )


def test_a_folder_written_before_a_new_step_key_is_the_same_recipe():
    """A key a later version added (None unless given) is not in an older folder's record."""
    from offline_evolution.recipes.runner import _what_runs

    step = {"step": "urdf", "run": "robot-from-urdf", "urdf": "a.urdf", "up": None}
    old = {"recipe": {"recipe": "x", "steps": [step]}, "budget": "full"}
    new = {"recipe": {"recipe": "x", "steps": [{**step, "turn": None, "stance": None}]}}
    assert _what_runs(old) == _what_runs({**new, "budget": "full"})
    given = {"recipe": {"recipe": "x", "steps": [{**step, "stance": 0.5}]}, "budget": "full"}
    assert _what_runs(old) != _what_runs(given)


GOOD_STEP = {"step": "rep", "run": "repertoire", "robot": "4ws-5", "settings": "rep.yaml",
             "seed": 1, "out": "rep.json"}  # fmt: skip


@pytest.mark.parametrize(
    ("steps", "message"),
    [
        ([{**GOOD_STEP, "sed": 1}], "steps[0] (rep): unknown setting 'sed' (did you mean 'seed'?)"),
        ([{**GOOD_STEP, "run": "mapelites"}], "steps[0]: run must be one of repertoire, arbit"),
        ([{**GOOD_STEP, "settings": "none.yaml"}], "steps[0] (rep): settings: no such file"),
        ([{**GOOD_STEP, "robot": "rover"}], "steps[0] (rep): robot must be one of"),
        ([{**GOOD_STEP, "out": "../x.json"}], "steps[0] (rep): out must be a plain name"),
        ([{**GOOD_STEP, "sha256": "abc"}], "steps[0] (rep): sha256 must be 64 lowercase hex"),
        ([GOOD_STEP, {**GOOD_STEP, "out": "b.json"}], "steps[1] (rep): step 'rep' is named twice"),
        (
            [{"step": "a", "run": "arbitrator", "repertoire": "rep", "settings": "rep.yaml",
              "seed": 1, "out": "a.json"}, GOOD_STEP],
            "steps[0] (a): repertoire: 'rep' is not an earlier step (earlier steps: none)",
        ),
        ([], "steps must be a list of at least one step"),
    ],
)  # fmt: skip
def test_bad_recipes_are_refused_in_one_line(steps, message, tmp_path, capsys):
    (tmp_path / "rep.yaml").write_text("seed: 1\n")
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"recipe": "bad", "steps": steps}))
    assert main(["recipe", str(path), "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"evorbc-evolve: error: {path}: ") and message in err
    assert not (tmp_path / "out").exists()


def test_an_unknown_top_level_key_is_refused(tmp_path, capsys):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"recipe": "bad", "step": [GOOD_STEP]}))
    assert main(["recipe", str(path)]) == 1
    err = capsys.readouterr().err
    assert "unknown setting 'step' (did you mean 'steps'?)" in err


def test_the_verdict_sets_wall_clock_times_aside(tmp_path):
    shipped = SHIPPED / "4ws-5-paper.arbitrator.json"
    data = json.loads(shipped.read_text())
    sha, content = file_sha256(shipped), content_sha256(shipped)
    assert Verdict.of(shipped, sha, content, None).text.startswith("reproduced: the shipped file,")
    data["evolution"]["seconds"] += 1.0
    data["evolution"]["history"][3]["evaluation_seconds"] *= 2
    rerun = tmp_path / "rerun.json"
    rerun.write_text(json.dumps(data, indent=1))
    verdict = Verdict.of(rerun, sha, content, None)
    assert verdict.reproduced and "but for its wall-clock times" in verdict.text
    data["evolution"]["best_fitness"] += 1e-12
    rerun.write_text(json.dumps(data))
    verdict = Verdict.of(rerun, sha, content, None)
    assert not verdict.reproduced and not verdict.known and "NOT reproduced" in verdict.text


def _arbitrator_steps():
    for path in RECIPES:
        recipe = load_recipe(path)
        for step in recipe.steps:
            if step.run == "arbitrator":
                yield pytest.param(recipe, step, id=f"{path.stem}-{step.step}")


@pytest.mark.parametrize(("recipe", "step"), list(_arbitrator_steps()))
def test_each_arbitrator_step_is_what_the_shipped_file_records(recipe, step):
    """Seed, length, task, NEAT file, selection and input names: the recipe's settings
    are the shipped run's (a setting edited since would fail here, not hours later)."""
    from offline_evolution.arbitrator.evolve import file_sha256 as neat_sha256
    from offline_evolution.arbitrator.settings import load_run_settings
    from offline_evolution.maze_task.task import MazeTaskSettings

    shipped = {file_sha256(p): p for p in SHIPPED.glob("*.json")}
    arb = ArbitratorFile.load(shipped[step.sha256])
    run = load_run_settings(step.settings)
    evolution = arb.evolution
    assert evolution["seed"] == step.seed
    assert evolution["generations"] == (step.generations or run.generations)
    assert evolution["task"] == MazeTaskSettings.load(step.task or run.task_path()).as_dict()
    assert evolution["neat_sha256"] == neat_sha256(step.neat or run.neat_path())
    assert arb.mapping == run.mapping
    post = evolution["post_evaluation"]
    # A file shipped before these were recorded was made with their defaults.
    recorded = (post.get("rule", "mean"), post.get("hall_of_fame", 25))
    assert recorded == (run.post_rule, run.hall_of_fame)
    assert arb.repertoire["file"] == recipe.step(step.repertoire).out
    if step.init_from:
        assert evolution["initial_network"]["file"] == recipe.step(step.init_from).out
    else:
        assert "initial_network" not in evolution
