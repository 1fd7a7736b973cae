"""``evorbc-evolve arbitrator``, ``standard`` and ``replay`` end to end (small budgets)."""

import json

import pytest

from evorbc_ros.arbitrator import ArbitratorFile
from offline_evolution.cli import main


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def evolved(tmp_path, capsys, small_repertoire, small_neat_file, small_task_file):
    rep = tmp_path / "r.json"
    small_repertoire.save(rep)
    out = tmp_path / "a.json"
    code, stdout, stderr = run(
        capsys,
        "arbitrator",
        "--repertoire",
        rep,
        "--generations",
        3,
        "--seed",
        2,
        "--neat-config",
        small_neat_file,
        "--task",
        small_task_file,
        "--out",
        out,
    )
    assert code == 0, stderr
    return out, rep, stdout, stderr


def test_arbitrator_writes_file_curve_and_summary(evolved, tmp_path):
    out, _, stdout, stderr = evolved
    assert stdout.startswith("4ws-5 arbitrator: best fitness") and len(stdout.splitlines()) == 1
    assert stderr.count("generation ") == 3 and "species" in stderr and "s/gen" in stderr
    assert (tmp_path / "a.fitness.png").read_bytes()[:4] == b"\x89PNG"
    arb = ArbitratorFile.load(out)
    assert arb.evolution["generations"] == 3 and len(arb.evolution["history"]) == 3
    assert not (tmp_path / "a.json.checkpoint.json").exists()


def small_run(tmp_path, repertoire, neat_file, task_file, generations: int) -> list:
    """``arbitrator`` arguments of a quiet small run (the repertoire saved in tmp_path)."""
    rep = tmp_path / "r.json"
    repertoire.save(rep)
    argv = ["arbitrator", "--repertoire", rep, "--generations", generations, "--seed", 2]
    return [*argv, "--quiet", "--neat-config", neat_file, "--task", task_file]


def test_the_population_and_the_post_selection_size_are_options(
    tmp_path, capsys, small_repertoire, small_neat_file, small_task_file
):
    argv = small_run(tmp_path, small_repertoire, small_neat_file, small_task_file, 2)
    out = tmp_path / "a.json"
    options = ["--population", 12, "--hall-of-fame", 1, "--post-samples", 1]
    code, _, err = run(capsys, *argv, *options, "--out", out)
    assert code == 0, err
    evolution = ArbitratorFile.load(out).evolution
    assert evolution["population"] == 12  # recorded: the NEAT file says 24
    post = evolution["post_evaluation"]
    assert post["samples_per_maze"] == 1 and post["hall_of_fame"] == 1
    # The best genome, the last generation's champion and one nominal reacher at most.
    assert 1 <= post["candidates"] <= 3
    code, _, err = run(capsys, *argv, "--out", tmp_path / "b.json")
    assert code == 0, err
    evolution = ArbitratorFile.load(tmp_path / "b.json").evolution
    assert "population" not in evolution  # the file's pop_size: files as before
    default = evolution["post_evaluation"]  # the run settings' (config/arbitrator/4ws.yaml)
    assert default["hall_of_fame"] == 25 and default["samples_per_maze"] == 10
    assert default["candidates"] > 3
    assert default["episodes_per_candidate"] > post["episodes_per_candidate"]
    # A population the file's species settings cannot hold is refused in one line.
    code, _, err = run(capsys, *argv, "--population", 3, "--out", tmp_path / "c.json")
    assert code != 0 and len(err.strip().splitlines()) == 1 and "pop_size 3" in err, err


def test_replay_reports_each_maze(evolved, tmp_path, capsys):
    out, _, _, _ = evolved
    code, stdout, err = run(
        capsys,
        "replay",
        "--arbitrator",
        out,
        "--json",
        "--plot",
        tmp_path / "t.png",
        "--heatmap",
        tmp_path / "h.png",
    )
    assert code == 0, err
    report = json.loads(stdout)
    assert [m["maze"] for m in report["mazes"]] == ["obstacle", "gaps"]
    assert {"reached", "time", "fitness"} <= set(report["mazes"][0])
    assert (tmp_path / "t.png").exists() and (tmp_path / "h.png").exists()
    code, stdout, _ = run(capsys, "replay", "--arbitrator", out, "--maze", "gaps")
    assert code == 0 and "gaps" in stdout and "obstacle" not in stdout
    assert "target reached in" in stdout


def test_replay_refuses_another_repertoire(evolved, tmp_path, capsys, small_repertoire):
    out, _, _, _ = evolved
    data = small_repertoire.to_dict()
    data["primitives"] = {k: v[:-1] for k, v in data["primitives"].items()}
    other = tmp_path / "other.json"
    other.write_text(json.dumps(data))
    code, _, err = run(capsys, "replay", "--arbitrator", out, "--repertoire", other)
    assert code == 1 and "does not match the arbitrator" in err and len(err.splitlines()) == 1
    code, _, err = run(
        capsys, "replay", "--arbitrator", out, "--repertoire", other, "--allow-mismatch"
    )
    assert code == 0 and "warning" in err


def test_standard_with_equal_budget_adds_25_generations(
    tmp_path, capsys, small_neat_file, small_task_file
):
    out = tmp_path / "s.json"
    code, stdout, err = run(
        capsys,
        "standard",
        "--robot",
        "2ws-2",
        "--generations",
        1,
        "--equal-budget",
        "--neat-config",
        small_neat_file,
        "--task",
        small_task_file,
        "--quiet",
        "--out",
        out,
    )
    assert code == 0, err
    arb = ArbitratorFile.load(out)
    assert arb.kind == "standard" and arb.evolution["generations"] == 26
    assert [p.name for p in arb.parameters] == ["speed", "angle_front"]
    assert "standard-NEAT controller" in stdout


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (
            ["arbitrator", "--repertoire", "missing.json", "--out", "a.json"],
            "missing.json: no such repertoire file",
        ),
        (["replay", "--arbitrator", "missing.json"], "missing.json: no such arbitrator file"),
        (
            ["standard", "--robot", "4ws-5", "--neat-config", "nope.ini", "--out", "a.json"],
            "nope.ini: no such NEAT settings file",
        ),
    ],
)
def test_bad_files_exit_with_one_line(tmp_path, capsys, monkeypatch, argv, needle):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, *argv)
    assert code == 1 and needle in err and len(err.strip().splitlines()) == 1


def test_bad_neat_settings_are_named(tmp_path, capsys, small_neat_file):
    bad = tmp_path / "bad.ini"
    bad.write_text(small_neat_file.read_text().replace("pop_size", "population"))
    code, _, err = run(
        capsys, "standard", "--robot", "4ws-5", "--neat-config", bad, "--out", tmp_path / "s.json"
    )
    assert code == 1 and str(bad) in err and "pop_size" in err


def test_replay_over_many_random_starts_reports_each_maze(evolved, capsys):
    out, _, _, _ = evolved
    code, stdout, err = run(
        capsys, "replay", "--arbitrator", out, "--start", "random", "--episodes", 3, "--json"
    )
    assert code == 0, err
    report = json.loads(stdout)
    assert [m["maze"] for m in report["mazes"]] == ["obstacle"] * 3 + ["gaps"] * 3
    assert len({tuple(m["start"]) for m in report["mazes"]}) == 6  # distinct starts
    per_maze = {row["maze"]: row for row in report["per_maze"]}
    for name in ("obstacle", "gaps"):
        episodes = [m for m in report["mazes"] if m["maze"] == name]
        row = per_maze[name]
        assert row["episodes"] == 3 and row["fell"] == 0  # wheeled robots do not fall
        assert row["reached"] == sum(m["reached"] for m in episodes)
        assert row["mean_fitness"] == pytest.approx(sum(m["fitness"] for m in episodes) / 3)
    code, stdout, _ = run(
        capsys, "replay", "--arbitrator", out, "--start", "random", "--episodes", 3
    )
    assert code == 0 and "random starts per maze" in stdout and "mean time reached" in stdout
    code, _, err = run(capsys, "replay", "--arbitrator", out, "--episodes", 3)
    assert code == 1 and "--start random" in err and len(err.splitlines()) == 1


def test_a_failed_write_keeps_the_finished_run_and_the_same_command_writes_it(
    tmp_path, capsys, monkeypatch, small_repertoire, small_neat_file, small_task_file
):
    import offline_evolution.plots.fitness as fitness

    rep = tmp_path / "r.json"
    small_repertoire.save(rep)

    def disk_full(history, path, **_):  # the disk fills up as the curve is written
        raise OSError(28, "No space left on device", str(path))

    monkeypatch.setattr(fitness, "plot_fitness_history", disk_full)
    argv = ["arbitrator", "--repertoire", rep, "--generations", 2, "--neat-config",
            small_neat_file, "--task", small_task_file, "--out", tmp_path / "a.json"]  # fmt: skip
    code, _, err = run(capsys, *argv)
    checkpoint = tmp_path / "a.json.checkpoint.json"
    last = err.strip().splitlines()[-1]  # after the progress lines, one line of error
    assert code == 1 and last.startswith("evorbc-evolve: error: ") and "No space left" in last
    assert f"the finished run is kept in {checkpoint}" in last and checkpoint.exists()
    monkeypatch.undo()
    code, _, err = run(capsys, *argv)
    assert code == 0 and "generation " not in err  # nothing evolved again: files written
    assert ArbitratorFile.load(tmp_path / "a.json").evolution["generations"] == 2
    assert not checkpoint.exists()


def test_restart_deletes_only_a_neat_checkpoint(tmp_path, capsys, small_repertoire):
    rep = tmp_path / "r.json"
    small_repertoire.save(rep)
    precious = tmp_path / "precious.json"
    precious.write_text('{"format": "evorbc-repertoire"}')
    code, _, err = run(capsys, "arbitrator", "--repertoire", rep, "--out", tmp_path / "a.json",
                       "--checkpoint", precious, "--restart")  # fmt: skip
    assert code == 1 and "--restart does not delete it" in err and precious.exists()
    code, _, err = run(capsys, "arbitrator", "--repertoire", rep, "--out", rep)
    assert code == 1 and "is the same file as --out" in err and rep.exists()


def test_progress_says_when_a_run_resumes_from_its_checkpoint(capsys):
    from offline_evolution.arbitrator.evolve import GenerationStats
    from offline_evolution.runs.console import GenerationPrinter

    def lines(first_generation, quiet=False):
        printer = GenerationPrinter(quiet=quiet, total=655)
        if first_generation:  # what evolve() calls on restoring a checkpoint
            printer.resumed(first_generation)
        for g in (first_generation, first_generation + 1):
            printer.generation_end(GenerationStats(g, 0.4, 0.1, 0.4, 3, 26.0, 25.0, 0), None)
        return capsys.readouterr().err.splitlines()

    fresh, resumed = lines(0), lines(100)
    assert [line.split()[1] for line in fresh] == ["1/655", "2/655"]
    assert resumed[0] == "resuming from the checkpoint: generations 1-100 of 655 are done"
    assert [line.split()[1] for line in resumed[1:]] == ["101/655", "102/655"]
    # --quiet keeps the resume, and only it.
    assert lines(100, quiet=True) == resumed[:1]


def test_the_eta_is_not_thrown_by_one_slow_generation(capsys):
    from offline_evolution.arbitrator.evolve import GenerationStats
    from offline_evolution.runs.console import GenerationPrinter

    printer = GenerationPrinter(quiet=False, total=110)
    for g, seconds in enumerate([30.0, 30.0, 300.0, 30.0]):  # generation 3 paused 270 s
        printer.generation_end(GenerationStats(g, 0.4, 0.1, 0.4, 3, seconds, seconds, 0), None)
    lines = capsys.readouterr().err.splitlines()
    # 107 generations left at 30 s each, the slow one shown as it was but not projected
    assert "300.00 s/gen  eta  53.5 min" in lines[2]
    assert lines[3].endswith("30.00 s/gen  eta  53.0 min")


def test_a_kept_checkpoint_continues_to_more_generations(
    tmp_path, capsys, small_repertoire, small_neat_file, small_task_file
):
    """--keep-checkpoint: a finished run of 2 generations goes on to 4 and writes what a
    straight run of 4 writes."""
    rep = tmp_path / "r.json"
    small_repertoire.save(rep)
    common = ["arbitrator", "--repertoire", rep, "--seed", 2, "--neat-config", small_neat_file]
    common += ["--task", small_task_file, "--quiet"]
    ckpt = tmp_path / "run.checkpoint.json"
    code, _, err = run(
        capsys,
        *common,
        "--generations",
        2,
        "--out",
        tmp_path / "two.json",
        "--checkpoint",
        ckpt,
        "--keep-checkpoint",
    )
    assert code == 0, err
    assert (
        ckpt.exists() and ArbitratorFile.load(tmp_path / "two.json").evolution["generations"] == 2
    )
    code, _, err = run(
        capsys, *common, "--generations", 4, "--out", tmp_path / "four.json", "--checkpoint", ckpt
    )
    assert code == 0, err
    assert not ckpt.exists()  # without the flag, a finished run's checkpoint goes
    code, _, err = run(capsys, *common, "--generations", 4, "--out", tmp_path / "straight.json")
    assert code == 0, err
    continued = ArbitratorFile.load(tmp_path / "four.json")
    straight = ArbitratorFile.load(tmp_path / "straight.json")
    assert continued.network.to_dict() == straight.network.to_dict()
    strip = [
        {k: v for k, v in h.items() if "seconds" not in k} for h in continued.evolution["history"]
    ]
    assert strip == [
        {k: v for k, v in h.items() if "seconds" not in k} for h in straight.evolution["history"]
    ]


def test_the_episode_time_is_an_option_recorded_with_the_controller(
    tmp_path, capsys, small_repertoire, small_neat_file, small_task_file
):
    argv = small_run(tmp_path, small_repertoire, small_neat_file, small_task_file, 1)
    argv += ["--population", 12, "--hall-of-fame", 1, "--post-samples", 1]
    code, _, err = run(capsys, *argv, "--episode-time", 3.5, "--out", tmp_path / "a.json")
    assert code == 0, err
    task = ArbitratorFile.load(tmp_path / "a.json").evolution["task"]
    assert task["episode_time"] == 3.5  # the task file says otherwise
    # replay reads it: its episodes last 3.5 s at most
    code, stdout, err = run(capsys, "replay", "--arbitrator", tmp_path / "a.json", "--json")
    assert code == 0, err
    assert all(m["time"] <= 3.5 for m in json.loads(stdout)["mazes"])
    # Not a whole number of 0.1 s cycles: refused in one line.
    code, _, err = run(capsys, *argv, "--episode-time", 3.55, "--out", tmp_path / "b.json")
    assert code != 0 and len(err.strip().splitlines()) == 1, err
    assert "--episode-time 3.55: episode_time must be a positive multiple" in err
