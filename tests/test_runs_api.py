"""The run API used directly, without the command line: settings in, files out, progress
through a reporter (offline_evolution/runs; docs/design.md section 20, "Runs")."""

import json

import pytest

from evorbc_ros.config import ConfigError
from evorbc_ros.controller_kinds import EVORBC
from offline_evolution.checkpoint import Interrupted
from offline_evolution.reporters import Reporter
from offline_evolution.runs.arbitrator import ArbitratorRun, arbitrator_run
from offline_evolution.runs.command_line import command_line
from offline_evolution.runs.repertoire import RepertoireRun, repertoire_run
from offline_evolution.runs.replay import ReplayRun, replay_run

#: A small 2ws-2 repertoire: an initial batch of 500 and 20 batches of 100.
REPERTOIRE = {"robot": "2ws-2", "seed": 1, "initial_batch": 500, "batch_size": 100}


class Collect(Reporter):
    """Every event a run tells, in order."""

    def __init__(self):
        self.events = []

    def search_start(self, settings):
        self.events.append(("start", settings.generations))

    def resumed(self, generations):
        self.events.append(("resumed", generations))

    def generation_end(self, stats, settings):
        self.events.append(("generation", stats.generation))

    def iteration_end(self, progress):
        self.events.append(("iteration", progress.iteration, progress.resumed_from))

    def warning(self, message):
        self.events.append(("warning", message))


def test_a_repertoire_then_an_arbitrator_run_tell_their_progress_and_print_nothing(
    tmp_path, capsys
):
    seen = Collect()
    rep = repertoire_run(
        RepertoireRun(**REPERTOIRE, iterations=20, out=str(tmp_path / "r.json")), [seen]
    )
    assert rep.out.is_file() and len(rep.repertoire) > 0 and rep.seed == 1
    # the initial batch of 500 in pieces of a batch (100), then the 20 iterations
    assert [e[1] for e in seen.events] == [0] * 5 + list(range(1, 21))
    arb = ArbitratorRun(
        kind=EVORBC, repertoire=str(rep.out), seed=1, generations=3, out=str(tmp_path / "a.json")
    )
    seen = Collect()
    done = arbitrator_run(arb, [seen])
    assert seen.events == [("start", 3), ("generation", 0), ("generation", 1), ("generation", 2)]
    written = json.loads(done.out.read_text())
    assert written["evolution"]["seed"] == 1 and len(written["evolution"]["history"]) == 3
    assert done.plot == tmp_path / "a.fitness.png" and done.plot.is_file()
    assert not (tmp_path / "a.json.checkpoint.json").exists()
    assert capsys.readouterr() == ("", "")  # reporters tell; the API prints nothing

    replayed = replay_run(ReplayRun(arbitrator=str(done.out)), [seen])
    assert [o.maze for o in replayed.outcomes] == written["evolution"]["task"]["mazes"]
    assert replayed.repertoire_path == str(rep.out)


def test_a_stopped_run_resumes_to_the_same_repertoire(tmp_path):
    whole = repertoire_run(RepertoireRun(**REPERTOIRE, iterations=6, out=str(tmp_path / "w.json")))
    run = RepertoireRun(
        **REPERTOIRE, iterations=6, checkpoint_every=1, out=str(tmp_path / "p.json")
    )
    seen = Collect()
    with pytest.raises(Interrupted):
        repertoire_run(run, [seen], should_stop=lambda: len(seen.events) >= 3)
    assert not (tmp_path / "p.json").exists()
    seen = Collect()
    resumed = repertoire_run(run, [seen])
    assert seen.events[0][2] is not None  # told where it resumed from
    assert resumed.out.read_bytes() == whole.out.read_bytes()


def test_bad_settings_are_one_line_before_any_work(tmp_path):
    run = ArbitratorRun(kind=EVORBC, repertoire=str(tmp_path / "r.json"), out=str(tmp_path))
    with pytest.raises(ConfigError, match=r"^--out .*: is a folder, expected a file name"):
        arbitrator_run(run)


def test_settings_state_the_command_they_are_equivalent_to():
    run = ArbitratorRun(kind=EVORBC, repertoire="r.json", seed=3, generations=5, out="a.json")
    assert command_line(run) == [
        "arbitrator", "--repertoire", "r.json", "--seed", "3", "--generations", "5",
        "--out", "a.json",
    ]  # fmt: skip
