"""The study report's parts that read runs: the ETA rule, the Fig. 12 grid and the pooled
replays of Fig. 14 and 18 (docs/design.md, the study section)."""

import io

import numpy as np
import pytest
from study_helpers import write_tiny_study

from offline_evolution.study.figures import bin_time_grid
from offline_evolution.study.folder import finished_runs
from offline_evolution.study.progress import StudyProgress, format_duration
from offline_evolution.study.results import RunResult, SettingResults
from offline_evolution.study.selection import aggregate_selection
from offline_evolution.study.spec import Run, load_study


def _run(setting: str, seed: int, approach: str = "evorbc") -> Run:
    return Run(setting, seed, {"approach": approach})


def test_eta_uses_the_setting_then_the_approach_then_every_run():
    a1, a2, a3 = (_run("a", s) for s in (1, 2, 3))
    b1, b2 = _run("b", 1), _run("b", 2)
    s1 = _run("s", 1, "standard")
    out = io.StringIO()
    p = StudyProgress("t", [a1, a2, a3, b1, b2, s1], parallel=2, stream=out)
    assert p.eta() is None and "eta unknown yet" in p.line()  # nothing measured
    p.finished(a1, 100.0, fresh=True)
    p.finished(a2, 300.0, fresh=True)
    # a3: its setting's median (200); b1, b2: the evorbc median (200); s1: every run's (200).
    assert p.expected(a3) == 200.0 and p.expected(b1) == 200.0 and p.expected(s1) == 200.0
    p.finished(b1, 50.0, fresh=False)
    assert p.expected(b2) == 50.0  # its own setting now
    assert p.expected(s1) == 100.0  # median of 100, 300, 50
    # Left: a3 200 + b2 50 + s1 100 over 2 at once.
    assert p.eta() == pytest.approx(175.0)
    p.start(a3)
    assert p.line() == "study t: 3 done, 1 running, 2 left, eta 3 min"
    p.fail(s1, "boom")
    assert p.eta() == pytest.approx(125.0)  # a failed run is no longer waited for
    assert (
        "failed s/seed-001: boom; study t: 3 done, 1 running, 1 left (1 failed)" in out.getvalue()
    )
    # Fewer runs left than slots: no gain from the idle slot.
    p.finished(a3, 200.0, fresh=True)
    assert p.eta() == pytest.approx(50.0)


def test_durations_read_naturally():
    assert [format_duration(s) for s in (12, 61, 3599, 3600, 3 * 3600 + 5 * 60)] == [
        "12 s", "1 min", "1 h 00 min", "1 h 00 min", "3 h 05 min",
    ]  # fmt: skip


def _result(summary, cpu=1.0, seconds=1.0, done=None, evolution_seconds=None) -> RunResult:
    return RunResult(1, done, seconds, cpu, "", summary, evolution_seconds, np.zeros(0))


def _setting(bin_size, eval_time, best, counts):
    runs = [
        _result({"best_fitness": b, "repertoire": {"count": c}})
        for b, c in zip(best, counts, strict=True)
    ]
    return SettingResults(
        f"{bin_size}-{eval_time}", {"bin_size": bin_size, "eval_time": eval_time}, runs
    )


def test_bin_time_grid_puts_each_setting_in_its_cell_and_leaves_gaps_empty():
    settings = [
        _setting(0.04, 2.0, [1.2, 1.4], [260, 280]),
        _setting(0.01, 2.0, [1.0], [4000]),
        _setting(0.04, 0.5, [0.8, 0.9, 1.0], [30, 40, 50]),
        _setting(0.01, 0.5, [], []),  # no finished run yet
    ]
    bins, times, size, fit = bin_time_grid(settings)
    assert bins == [0.01, 0.04] and times == [0.5, 2.0]
    assert size.shape == fit.shape == (2, 2)
    assert fit[1, 1] == pytest.approx(1.3) and size[1, 1] == pytest.approx(270)
    assert fit[1, 0] == pytest.approx(1.0) and size[1, 0] == pytest.approx(4000)
    assert fit[0, 1] == pytest.approx(0.9) and size[0, 1] == pytest.approx(40)
    assert np.isnan(fit[0, 0]) and np.isnan(size[0, 0])


@pytest.mark.slow
def test_selection_pools_every_cycle_of_every_runs_nominal_replays(serial_results, tmp_path):
    study = load_study(write_tiny_study(tmp_path))
    ((_, _, runs),) = finished_runs(study, serial_results)
    assert len(runs) == 2
    outputs, chosen, reach = aggregate_selection(runs)
    one = [aggregate_selection([r]) for r in runs]
    # Pooled over the runs, in run order.
    assert np.array_equal(outputs, np.concatenate([o for o, _, _ in one]))
    assert np.array_equal(chosen, np.concatenate([c for _, c, _ in one]))
    assert reach == max(r for _, _, r in one)
    for run, (o, c, r) in zip(runs, one, strict=True):
        rep = run.repertoire()
        assert len(o) == len(c) > 0
        assert np.all((o >= 0) & (o <= 1))  # mapping outputs
        # Every chosen displacement is one of the run's primitives.
        assert all(np.any(np.all(rep.behaviour == row, axis=1)) for row in c)
        assert r == pytest.approx(np.max(np.abs(rep.behaviour)))


def _costed(setting_id, approach, cpu, seconds, done, ran, evolution_seconds):
    run = _result({"generations": ran}, cpu, seconds, done, evolution_seconds)
    values = {"approach": approach, "generations": 1000}
    return SettingResults(setting_id, values, [run])


def test_full_protocol_cost_scales_the_evolution_only_and_imputes_by_approach():
    from offline_evolution.study.report import _fixed_share, _full_cpu, _imputed

    # EvoRBC: half its wall time outside evolution (a PyBullet repertoire), 300 of 1000.
    evo = _costed("e", "evorbc", cpu=100.0, seconds=200.0, done=300, ran=300,
                  evolution_seconds=100.0)  # fmt: skip
    assert _fixed_share(evo.runs[0]) == pytest.approx(0.5)
    assert _full_cpu(evo, evo.runs[0], 0.5) == pytest.approx(100 * (0.5 + 0.5 * 1000 / 300))
    # Standard NEAT at equal budget: 300 asked, 325 run; the full run is 1025 generations.
    std = _costed("s", "standard", cpu=65.0, seconds=65.0, done=300, ran=325,
                  evolution_seconds=65.0)  # fmt: skip
    assert _fixed_share(std.runs[0]) == 0.0
    assert _full_cpu(std, std.runs[0]) == pytest.approx(65 * 1025 / 325)
    # A setting without runs is costed at its own approach's measured mean.
    missing = SettingResults("m", {"approach": "standard", "generations": 1000})
    per_run = {"e": 500.0, "s": 200.0}
    assert _imputed(missing, [evo, std, missing], per_run) == 200.0
    assert _imputed(evo, [evo, std, missing], per_run) == 500.0
