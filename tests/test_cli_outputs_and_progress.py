"""evorbc-evolve: outputs checked before any work, one-line argument errors with one exit
status, and an ETA that is not wild at the start."""

import pytest

from offline_evolution.cli import main
from offline_evolution.repertoire.map_elites import Progress
from offline_evolution.runs.console import GenerationPrinter, IterationPrinter


def run(capsys, *argv):
    try:
        code = main([str(a) for a in argv])
    except SystemExit as e:
        code = e.code
    err = capsys.readouterr().err.strip()
    assert "internal error" not in err and "Traceback" not in err, err
    assert len(err.splitlines()) == 1, err
    return code, err


@pytest.fixture
def no_evolution(monkeypatch):
    def fail(*a, **k):
        raise AssertionError("the run started")

    monkeypatch.setattr("offline_evolution.arbitrator.evolve.evolve", fail)
    monkeypatch.setattr("offline_evolution.repertoire.map_elites.generate_repertoire", fail)


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--plot", "a.xyz"], "--plot a.xyz: not a picture format that can be written"),
        (["--plot", "."], "--plot .: is a folder, expected a file name"),
        (["--out", "sub"], "--out sub: is a folder, expected a file name"),
    ],
)
@pytest.mark.parametrize("command", ["arbitrator", "standard"])
def test_evolution_outputs_are_refused_before_evolving(
    tmp_path, capsys, monkeypatch, no_evolution, small_repertoire, command, argv, needle
):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    small_repertoire.save(tmp_path / "r.json")
    which = ["--repertoire", "r.json"] if command == "arbitrator" else ["--robot", "4ws-5"]
    options = dict(zip(argv[::2], argv[1::2], strict=True))
    out = options.pop("--out", "a.json")
    code, err = run(capsys, command, *which, "--out", out, *sum(options.items(), ()))
    assert code == 1 and err.startswith(f"evorbc-evolve: error: {needle}")


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--plot", "r.xyz"], "--plot r.xyz: not a picture format that can be written"),
        (["--csv", "sub"], "--csv sub: is a folder, expected a file name"),
    ],
)
def test_repertoire_outputs_are_refused_before_the_run(
    tmp_path, capsys, monkeypatch, no_evolution, argv, needle
):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    code, err = run(capsys, "repertoire", "--out", "r.json", *argv)
    assert code == 1 and err.startswith(f"evorbc-evolve: error: {needle}")


def test_a_mistyped_robot_is_one_line(capsys):
    code, err = run(capsys, "repertoire", "--robot", "4ws5", "--out", "r.json")
    assert code == 2 and err.startswith(
        "evorbc-evolve repertoire: error: argument --robot: invalid choice: '4ws5'"
    )
    assert "usage:" not in err


@pytest.mark.parametrize("value", ["-3", "0", "two"])
def test_every_bad_generations_value_is_refused_the_same_way(capsys, value):
    code, err = run(capsys, "standard", "--robot", "4ws-5", "--generations", value, "--out", "a")
    assert code == 2
    assert err.startswith("evorbc-evolve standard: error: argument --generations: expected an ")
    assert err.endswith("(see evorbc-evolve standard --help)")


# -- ETA -------------------------------------------------------------------------------------


class Stats:
    def __init__(self, generation, seconds):
        self.generation, self.seconds = generation, seconds
        self.best = self.mean = self.best_so_far = 0.5
        self.species, self.best_reached = 3, 0


def test_the_generation_eta_leaves_out_the_compiling_first_generation(capsys):
    printer = GenerationPrinter(False, 40)
    # The first generation compiles (12 s); the others take 0.5 s: 20 s in all.
    for g, seconds in enumerate([12.0, 0.5, 0.5, 0.5, 0.6]):
        printer.generation_end(Stats(g, seconds), None)
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].endswith("s/gen  eta   --") and lines[1].endswith("s/gen  eta   --")
    assert lines[2].endswith("eta   0.3 min")  # 37 generations x 0.5 s, not x 12 s
    assert lines[4].endswith("eta   0.3 min")


def test_the_last_generation_says_done(capsys):
    printer = GenerationPrinter(False, 2)
    printer.generation_end(Stats(0, 3.0), None)
    printer.generation_end(Stats(1, 0.5), None)
    assert capsys.readouterr().err.splitlines()[-1].endswith("done")


def progress(evaluations, elapsed, total=100_000):
    return Progress(
        iteration=evaluations // 1000,
        iterations=total // 1000,
        evaluations=evaluations,
        cells=10,
        mean_quality=0.5,
        qd_score=5.0,
        elapsed=elapsed,
        total_evaluations=total,
    )


def test_the_repertoire_eta_uses_the_batches_after_the_first(capsys):
    printer = IterationPrinter(interval=0.0)
    # 1000 evaluations a batch: the first took 10 s (start-up), the others 0.5 s each.
    for k in range(8):
        printer.iteration_end(progress(1000 * (k + 1), 10.0 + 0.5 * k))
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].endswith("eta   --") and lines[3].endswith("eta   --")
    # 2000 evaluations/s after the first batch: 92,000 left take 0.8 min (not 7.7).
    assert lines[5].endswith("2000.0 eval/s  eta    0.8 min")
