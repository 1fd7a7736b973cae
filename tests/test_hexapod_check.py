"""The hexapod paper-check summary: the figures it reports come from the run files."""

import json

import pytest
from hexapod_helpers import tripod_repertoire
from neat_helpers import neat_config, network_spec, random_genomes

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.config import config_dir
from evorbc_ros.robots.hexapod import parameter_specs
from evorbc_ros.sensors import SensorLayout
from offline_evolution.checkpoint import CheckpointError
from offline_evolution.experiments.hexapod_check import summarise

TASK = {"mazes": ["hexapod"], "episode_time": 2.0, "samples_per_maze": 1,
        "sensors": "sensors/hexapod.yaml"}  # fmt: skip


def evolution(seed, best, first_reach, post_fitness, post_reached, rule=None, generations=10):
    """An ``evolution`` record as the CLI writes it; fitness climbs 0.01 a generation."""
    history = [
        {"generation": g, "best_reached": int(first_reach is not None and g >= first_reach),
         "best": 0.01 * g, "best_so_far": 0.01 * g}
        for g in range(generations)
    ]  # fmt: skip
    return {
        "seed": seed, "generations": generations, "best_fitness": best, "history": history,
        "best_reached": int(first_reach is not None), "task": TASK,
        "post_evaluation": {"fitness": post_fitness, "reached": post_reached,
                            "episodes_per_candidate": 21, **({"rule": rule} if rule else {})},
    }  # fmt: skip


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = tmp_path_factory.mktemp("check")
    rep = tripod_repertoire()
    rep.save(out / "rep.json")
    layout = SensorLayout.load(config_dir() / "sensors" / "hexapod.yaml")
    config = neat_config(6, 2, path="config/neat/hexapod.ini")
    runs = ((1, 1.2, 6, (0.9, 0.5, None)), (2, 1.3, None, (0.7, 0.1, "nominal_then_mean")))
    sizes = {"evorbc": [], "standard": []}  # neat-python's own count: genome.size()
    for seed, best, first, post in runs:
        genome = random_genomes(config, 1, seed=seed)[0]
        sizes["evorbc"].append(sum(genome.size()))
        ArbitratorFile(
            kind="evorbc", robot="hexapod", sensors=layout, mapping="polar",
            network=network_spec(genome, config),
            repertoire={"fingerprint": rep.fingerprint(), "robot": "hexapod", "count": 6},
            evolution=evolution(seed, best, first, *post),
        ).save(out / f"evorbc-seed{seed}.json")  # fmt: skip
    config37 = neat_config(6, 37, path="config/neat/hexapod.ini")
    genome = random_genomes(config37, 1, seed=3)[0]
    sizes["standard"].append(sum(genome.size()))
    ArbitratorFile(
        kind="standard", robot="hexapod", sensors=layout, parameters=parameter_specs(),
        network=network_spec(genome, config37),
        # 5 + the 455 of the equal budget, so EvoRBC's budget is 5 generations
        evolution=evolution(1, 0.4, None, 0.3, 0.0, generations=460),
    ).save(out / "standard-seed1.json")  # fmt: skip
    return out, sizes


def test_summary_reports_the_runs_next_to_the_paper(runs):
    runs, sizes = runs
    text = summarise(runs / "rep.json", runs, [1, 2, 3], [1])
    rows = {line.split(" | ")[0]: line for line in text.splitlines()}
    assert "| 6 primitives" in rows["| repertoire size"]
    # seed 3 has not run: the mean and sd are over the two finished runs, and generations
    # count from 1 as the CLI's progress lines do
    evo = rows["| EvoRBC best fitness, 2 run(s) of 10 generations"]
    assert "1.25 ± 0.07; goal reached in 1 of 2; first reached at generation 7, never" in evo
    post = next(v for k, v in rows.items() if k.startswith("| selected EvoRBC"))
    # a random network 2 s into the maze does not reach; the rule is recorded per seed
    assert "seed 1 (rule mean): 0.90, reached 50 % of 21, misses from the nominal start" in post
    assert "seed 2 (rule nominal_then_mean): 0.70, reached 10 % of 21, misses" in post
    assert any(k.startswith("| primitive switches") for k in rows)
    std = rows["| standard NEAT, 1 run(s) of 460 generations"]
    # generation 5 is history entry 4: best so far 0.04
    assert (
        "best fitness 0.40 (0.04 at generation 5, EvoRBC's budget), goal reached in 0 of 1" in std
    )
    assert "% of the way" in std
    size = next(v for k, v in rows.items() if k.startswith("| network size"))
    evo_size = (sizes["evorbc"][0] + sizes["evorbc"][1]) / 2
    assert f"EvoRBC {evo_size:.1f} (2 run(s)), standard NEAT {sizes['standard'][0]:.1f} (1" in size
    assert sizes["standard"][0] > max(sizes["evorbc"])  # 37 outputs against 2
    assert (runs / "hexapod-check.md").read_text() == text
    assert (runs / "hexapod-check.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_an_unfinished_standard_run_is_reported_from_its_checkpoint(runs, tmp_path):
    runs, _ = runs
    # 660 generations (200 + the 455 of the equal budget + 5 more than run): the row
    # reports how far it has got and the best so far at EvoRBC's budget, generation 200
    best = [0.1 + 0.001 * g for g in range(250)]
    history = [{"best_so_far": b, "best_reached": 0} for b in best]
    ckpt = {"settings": {"generations": 660}, "history": history}
    (tmp_path / "standard-seed1.json.checkpoint.json").write_text(json.dumps(ckpt))
    text = summarise(runs / "rep.json", tmp_path, [], [1])
    row = next(line for line in text.splitlines() if "still running" in line)
    assert "seed 1: generation 250 of 660, best fitness so far 0.35 (generation 250)" in row
    assert "goal not reached; 0.30 at generation 205 (EvoRBC's budget)" in row
    (tmp_path / "standard-seed1.json.checkpoint.json").write_text('{"settings": {}}')
    with pytest.raises(CheckpointError, match="not a NEAT checkpoint with a generation history"):
        summarise(runs / "rep.json", tmp_path, [], [1])


def test_another_legged_robot_has_no_paper_column_and_its_own_budget(runs, tmp_path):
    """The A1's comparison (docs/a1.md): no paper values; the stated extra generations."""
    from offline_evolution.experiments.legged_check import summarise as legged_summarise

    runs, _ = runs
    history = [{"best_so_far": 0.01 * g, "best_reached": int(g > 30)} for g in range(40)]
    ckpt = {"settings": {"generations": 100}, "history": history}
    (tmp_path / "evorbc-seed1.json.checkpoint.json").write_text(json.dumps(ckpt))
    ckpt = {"settings": {"generations": 233}, "history": history[:20]}
    (tmp_path / "standard-seed1.json.checkpoint.json").write_text(json.dumps(ckpt))
    text = legged_summarise(runs / "rep.json", tmp_path, [1], [1], "a1", standard_extra=133)
    lines = text.splitlines()
    assert lines[:2] == ["| figure | here |", "|---|---|"]
    assert all(line.count(" | ") == 1 for line in lines if line.startswith("| "))
    evo = next(line for line in lines if line.startswith("| EvoRBC still running"))
    assert "seed 1: generation 40 of 100, best fitness so far 0.39 (generation 40)" in evo
    assert "goal reached" in evo
    std = next(line for line in lines if line.startswith("| standard NEAT still running"))
    assert "generation 20 of 233" in std and "EvoRBC's budget" not in std  # 100 not yet run
    assert (tmp_path / "a1-check.md").read_text() == text
