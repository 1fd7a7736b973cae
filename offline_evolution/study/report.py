"""``evorbc-study report``: a study's figures, statistics and verdicts, as Markdown.

Everything comes from the results folder (the runs' ``run.json`` and files) or from the
study's compact result table made from it (``table.py``), so a report can be regenerated
at any time, also while a study is still running (it then says how many runs each setting
has so far). Both are read into the same objects (``results.py``) first, so the report of
a folder and that of its table are the same.
"""

from __future__ import annotations

import math
import os
import statistics
from dataclasses import replace
from pathlib import Path

import numpy as np

from evorbc_ros.atomic_io import atomic_write
from offline_evolution.study import figures
from offline_evolution.study.folder import load_results
from offline_evolution.study.results import RunResult, SettingResults, protocol
from offline_evolution.study.spec import Study
from offline_evolution.study.stats import ALPHA, ClaimResult, evaluate_claims

#: Figures a study draws unless its file lists others (``figures:``).
DEFAULT_FIGURES = ("curves", "boxplots", "repertoires")
#: Cluster shapes for the projected cost of the full protocol: (machines, cores each).
CLUSTERS = ((1, 2), (4, 16), (16, 32))


def read_results(
    study: Study, results: Path, replay_runs: int | None = None
) -> tuple[list[SettingResults], dict | None]:
    """A study's results from a results folder or, if ``results`` is a file, its table.

    Args:
        replay_runs: at most this many runs per setting are replayed for the selection
            heatmaps (default: all); a table holds the counts it was made with.

    Returns:
        The settings, and the table's header (None for a folder).

    Raises:
        ValueError: a malformed table, or ``replay_runs`` with a table.
    """
    if results.is_file():
        from offline_evolution.study.table import read_table

        header, settings = read_table(results, study)
        if replay_runs is not None:
            raise ValueError(
                f"--replay-runs: {results} is a result table, whose selection counts were "
                "made when it was compacted (evorbc-study compact --replay-runs)"
            )
        return settings, header
    selection = "selection" in (study.figures or DEFAULT_FIGURES)
    return load_results(study, results, selection, replay_runs), None


def write_report(study: Study, results: Path, out: Path, replay_runs: int | None = None) -> Path:
    """Draw the study's figures into ``out`` and write ``out/<study>.md``.

    Args:
        results: the results folder, or the study's compact result table.
        replay_runs: see :func:`read_results`.

    Returns:
        The Markdown file.
    """
    settings, header = read_results(study, results, replay_runs)
    if not any(s.runs for s in settings):
        raise ValueError(f"{results}: no finished run of study {study.name}")
    out.mkdir(parents=True, exist_ok=True)
    keys = list(study.grid)
    samples = [(s.values, s.best) for s in settings if s.runs]
    claims = evaluate_claims(study.compare, samples)
    drawn = _draw(study, settings, keys, out)
    text = _markdown(study, settings, keys, claims, drawn, (results, header), out)
    md = out / f"{study.name}.md"
    atomic_write(md, lambda f: f.write(text))
    return md


def _draw(study: Study, settings, keys, out: Path) -> list[tuple[str, str]]:
    """Draw the figures; returns ``(caption, file name)`` pairs."""
    from evorbc_ros.robots.registry import DEFAULT_ROBOT, lookup

    wanted = study.figures or DEFAULT_FIGURES
    drawn = []
    name = study.name
    if "curves" in wanted:
        panel, lines = _curve_layout(keys)
        shift = None
        # Shifted only when every robot's repertoire costs as many generations: with
        # several costs, one shift would be wrong for some curves.
        budgets = {
            lookup(s.values.get("robot") or DEFAULT_ROBOT).equal_budget_generations
            for s in settings
        }
        if "approach" in keys and len(budgets) == 1:
            shift = {"evorbc": budgets.pop()}
        path = out / f"{name}-fitness.png"
        figures.fitness_curves(settings, panel, lines, path, shift, study.title)
        what = "Highest fitness so far, mean over runs with the min-max band"
        if shift:
            what += (
                f"; EvoRBC's curves start after the {shift['evorbc']} generations its repertoire "
                "cost (equal budget)"
            )
        drawn.append((what + ".", path.name))
    if "boxplots" in wanted:
        path = out / f"{name}-boxplot.png"
        figures.boxplots(settings, keys, path, study.title)
        drawn.append(
            ("Each run's highest fitness (boxes: quartiles, whiskers: 1.5 IQR).", path.name)
        )
    if "repertoires" in wanted and any(
        s.values.get("approach", "evorbc") == "evorbc" for s in settings
    ):
        path = out / f"{name}-repertoires.png"
        grid = ("eval_time", "bin_size") if {"eval_time", "bin_size"} <= set(keys) else None
        evorbc = [s for s in settings if s.values.get("approach", "evorbc") == "evorbc"]
        figures.example_repertoires(evorbc, [k for k in keys if k != "approach"], path, grid)
        drawn.append(("An example repertoire per setting (each setting's first seed).", path.name))
    if "heatmaps" in wanted:
        path = out / f"{name}-heatmaps.png"
        figures.bin_time_heatmaps(settings, path)
        drawn.append(
            (
                "Mean repertoire size and mean highest fitness per bin size and evaluation time.",
                path.name,
            )
        )
    if "selection" in wanted:
        panels = []
        for s in settings:
            if s.runs and s.selection is not None:
                label = figures.setting_label(s.values, [k for k in keys if k != "approach"])
                panels.append((label or s.values.get("robot", ""), s.selection))
        if panels:
            path = out / f"{name}-selection.png"
            figures.selection_heatmaps(panels, path)
            drawn.append(
                (
                    "Mapping outputs (top) and the displacement of the chosen primitives "
                    "(bottom) of every run's written controller, from each maze's nominal "
                    "start, aggregated over the runs.",
                    path.name,
                )
            )
    return drawn


def _curve_layout(keys: list[str]) -> tuple[str | None, list[str]]:
    """Panels by one key and curves by the other, or one panel with a curve per setting."""
    if len(keys) == 2:
        if "approach" in keys:
            other = next(k for k in keys if k != "approach")
            return other, ["approach"]
        return keys[1], [keys[0]]
    return None, keys


def _fmt(x: float, digits: int = 3) -> str:
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}f}"


def _p(p: float) -> str:
    if p is None or math.isnan(p):
        return "n/a"
    return "< 0.001" if p < 0.001 else f"{p:.3f}"


def _markdown(study, settings: list[SettingResults], keys, claims, drawn, source, out) -> str:
    proto = protocol(settings)
    gens = ", ".join(map(str, proto["generations"])) or "n/a"
    lines = [
        f"# Study: {study.title}",
        "",
        *_provenance(study, settings, source, out),
        "",
        "## Protocol",
        "",
        f"* Settings: {len(settings)} ({', '.join(keys)} over the grid of "
        f"[config/studies/{Path(study.source).name}](../../config/studies/{Path(study.source).name})).",
        f"* Runs finished: {proto['runs']}, {_span(proto['min_seeds'], proto['max_seeds'])} "
        f"seeds per setting (the full protocol has {study.seeds}).",
        f"* NEAT generations per run: {gens}{_full_generations(study, settings)}.",
        "* Each run: its own repertoire (EvoRBC) and arbitrator, or a standard-NEAT "
        "controller, seeded by the run's seed; the figure is the run's highest training "
        "fitness (eq. 5, mean over the five mazes; 1 or more: every target reached).",
        "",
        "## Results per setting",
        "",
    ]
    header = [*keys, "runs", "highest fitness (mean ± sd)", "median", "min-max", "post-eval."]
    has_rep = any(s.values.get("approach", "evorbc") == "evorbc" for s in settings)
    if has_rep:
        header += ["primitives (mean ± sd)", "mean quality"]
    lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for s in settings:
        row = [figures.setting_label(s.values, [k]) for k in keys]
        if not s.runs:
            lines.append(
                "| " + " | ".join([*row, "0"] + ["" for _ in header[len(row) + 1 :]]) + " |"
            )
            continue
        b = s.best
        sd = float(np.std(b, ddof=1)) if len(b) > 1 else math.nan
        row += [
            str(len(b)),
            f"{_fmt(b.mean())} ± {_fmt(sd)}",
            _fmt(float(np.median(b))),
            f"{_fmt(b.min())}-{_fmt(b.max())}",
            _fmt(float(np.nanmean(s.summary("post_fitness")))),
        ]
        if has_rep:
            count = s.summary("repertoire.count")
            if np.all(np.isnan(count)):
                row += ["", ""]
            else:
                sdc = float(np.nanstd(count, ddof=1)) if len(count) > 1 else math.nan
                row += [
                    f"{np.nanmean(count):.0f} ± {_fmt(sdc, 0)}",
                    _fmt(float(np.nanmean(s.summary("repertoire.mean_quality")))),
                ]
        lines.append("| " + " | ".join(row) + " |")
    lines += [
        "",
        "*post-eval.*: the written controller's mean fitness over each maze's nominal start "
        "and seeded random starts (the run's post-evaluation).",
        "",
        "## The paper's claims",
        "",
        f"Two-sided Mann-Whitney U tests and Kruskal-Wallis tests (scipy), p-values adjusted "
        f"with Holm-Bonferroni within each family of comparisons, significance at "
        f"{ALPHA}. Effect sizes: Vargha-Delaney A12 (the chance that a run of the first "
        "setting beats one of the second; 0.5 = no effect), epsilon-squared, Pearson's r. "
        "A claim of *no difference* holds when no test finds one and no pairwise effect "
        "is large (A12 strictly between 0.29 and 0.71); with few runs that is weak "
        "evidence. A claim that one setting is *not worse* than another does not hold if "
        "it is significantly lower, is inconclusive if it loses by a large effect that is "
        "not significant (A12 at most 0.29), and holds otherwise. A claim that a setting "
        "is *best* holds only "
        "if it leads and is "
        "significantly above every other setting.",
        "",
    ]
    lines += _claims_table(claims)
    lines += ["", "## Figures", ""]
    for caption, name in drawn:
        lines += [f"![{caption}]({name})", "", caption, ""]
    lines += _costs(study, settings)
    return "\n".join(lines) + "\n"


def _provenance(study: Study, settings, source: tuple[Path, dict | None], out) -> list[str]:
    """Where the page comes from, and the commands that made its runs."""
    results, header = source
    report = f"`evorbc-study report {study.name} --results {results} --out {out}`"
    if header is None:
        made = f"{report} from the results folder alone"
        folder = results
    else:
        made = (
            f"{report} from the study's compact result table alone (every run's record and "
            "highest fitness per generation, the example repertoires and the selection "
            "counts; [docs/study.md](../study.md#compact-result-tables) describes it)"
        )
        folder = header["results"]
    text = (
        f"The paper's {study.paper}, rerun with `evorbc-study`. This page is written by "
        f"{made}; rerun it to update it."
    )
    if header is not None and header["source"]:
        text += f" The raw run folders are in {header['source']}."
    proto = protocol(settings)
    run = f"evorbc-study run {study.name} --results {folder}"
    if proto["max_seeds"] != study.seeds:
        run += f" --seeds {proto['max_seeds']}"
    full = {s.values.get("generations") for s in settings}
    if len(proto["generations"]) == 1 and full != set(proto["generations"]):
        run += f" --generations {proto['generations'][0]}"
    text += f" The runs were made by `{run}`"
    if header is not None:
        compact = f"evorbc-study compact {study.name} --results {folder} --out {results}"
        text += f" and compacted by `{compact}`"
    return [text + "."]


def _claims_table(claims: list[ClaimResult]) -> list[str]:
    out = [
        "| claim | paper | comparison | means | p | adjusted p | effect | verdict |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for c in claims:
        for k, comp in enumerate(c.comparisons):
            means = " vs ".join(_fmt(m) for m in comp.means)
            effect = f"{comp.effect_name} {_fmt(comp.effect, 2)}" if comp.effect_name else ""
            if comp.note:
                effect = f"{effect}; {comp.note}" if effect else comp.note
            first = k == 0
            out.append(
                "| "
                + " | ".join(
                    [
                        c.claim if first else "",
                        c.paper if first else "",
                        f"{comp.label} (n = {', '.join(map(str, comp.sizes))})",
                        means,
                        _p(comp.p),
                        _p(comp.p_adjusted),
                        effect,
                        f"**{c.verdict}**" if first else "",
                    ]
                )
                + " |"
            )
    return out


def _costs(study: Study, settings: list[SettingResults]) -> list[str]:
    """Measured cost per run and the projected cost of the full protocol."""
    out = ["## Cost", ""]
    rows, per_run = [], {}  # setting id -> full-protocol CPU s per run
    for s in settings:
        if not s.runs:
            continue
        wall = statistics.median(r.seconds for r in s.runs)
        cpu = statistics.median(r.cpu_seconds for r in s.runs)
        first = s.runs[0]
        gens = first.summary.get("generations") or first.generations
        scale = _full_cpu(s, replace(first, cpu_seconds=1.0), _fixed_share(first))
        per_run[s.setting_id] = cpu * scale
        machine = first.machine
        rows.append(
            f"| {figures.setting_label(s.values, list(study.grid))} | {wall / 60:.1f} | "
            f"{cpu / 60:.1f} | {gens} | {cpu * scale / 60:.1f} | {machine} |"
        )
    full_cpu = study.seeds * sum(_imputed(s, settings, per_run) for s in settings)
    measured, total = len(rows), len(settings)
    partial = (
        f" ({measured} of {total} settings measured; each other one is taken at the mean "
        "of the measured settings of its approach)"
        if measured < total
        else ""
    )
    out += [
        "Measured per run (median over the setting's runs; one numba thread per run, on a "
        "machine shared with other work, so wall times are upper bounds; the CPU time is "
        "the run's own). The full-protocol column scales the CPU time by the generations "
        "of the full protocol (standard NEAT's equal-budget generations included); the "
        "part of an EvoRBC run outside arbitrator evolution (its repertoire: seconds for a "
        "4WS robot, hours for a PyBullet one) is fixed, estimated from the arbitrator "
        "file's evolution time against the run's wall time.",
        "",
        "| setting | wall min/run | CPU min/run | generations | CPU min/run, full | machine |",
        "|---|---|---|---|---|---|",
        *rows,
        "",
        f"The full protocol ({study.seeds} seeds per setting) is about {full_cpu / 3600:.0f} "
        f"CPU hours{partial}. Runs are independent and take one core each, so on a cluster "
        "of N machines with M cores it takes about that divided by N x M, or the longest "
        "single run if that is longer:",
        "",
        "| machines x cores | wall time |",
        "|---|---|",
    ]
    longest = max(
        (_full_cpu(s, r, _fixed_share(r)) for s in settings for r in s.runs),
        default=0.0,
    )
    for n, m in CLUSTERS:
        hours = max(full_cpu / (n * m), longest) / 3600
        out.append(f"| {n} x {m} | {hours:.1f} h |")
    return [*out, ""]


def _full_cpu(setting: SettingResults, run: RunResult, fixed: float = 0.0) -> float:
    """A run's CPU seconds scaled to the full protocol's generations (the study file's).

    A standard-NEAT run at equal budget ran more generations than asked (the repertoire's
    evaluations as extra generations, ``summary.generations``); the extra is the same at
    any length, so the full run has it too. ``fixed``: the share of the run that does not
    grow with generations (an EvoRBC run's repertoire, :func:`_fixed_share`).
    """
    done = run.generations
    full = setting.values.get("generations")
    if not (done and full):
        return run.cpu_seconds
    extra = _extra_generations(run)
    grows = (full + extra) / (done + extra)
    return run.cpu_seconds * (fixed + (1.0 - fixed) * grows)


def _extra_generations(run: RunResult) -> int:
    """Generations a run ran beyond those asked (standard NEAT at equal budget), else 0."""
    asked = run.generations
    ran = run.summary.get("generations")
    return ran - asked if asked and ran else 0


def _fixed_share(run: RunResult) -> float:
    """The share of a run's time outside arbitrator evolution, in [0, 1].

    From the arbitrator file's evolution seconds against the run's wall seconds: the
    commands run one after the other, so the rest is the repertoire (EvoRBC) and the
    commands' start-up; CPU is assumed to split the same way.
    """
    evolution, total = run.evolution_seconds, run.seconds
    if evolution is None or math.isnan(evolution):
        return 0.0
    return min(1.0, max(0.0, 1.0 - evolution / total)) if total > 0 else 0.0


def _imputed(setting: SettingResults, settings: list[SettingResults], per_run: dict) -> float:
    """Full-protocol CPU s per run of ``setting``: measured, else its approach's mean."""
    if setting.setting_id in per_run:
        return per_run[setting.setting_id]
    approach = setting.values.get("approach", "evorbc")
    same = [
        per_run[s.setting_id]
        for s in settings
        if s.setting_id in per_run and s.values.get("approach", "evorbc") == approach
    ]
    pool = same or list(per_run.values())
    return statistics.fmean(pool) if pool else 0.0


def _full_generations(study: Study, settings: list[SettingResults]) -> str:
    """`` (the full protocol: 1000, ...)`` for the protocol line of the report."""
    full = sorted({s.values.get("generations") for s in settings} - {None})
    extra = sorted({_extra_generations(r) for s in settings for r in s.runs} - {0})
    text = f" (the full protocol: {', '.join(map(str, full))})" if full else ""
    if extra:
        text += (
            f"; standard NEAT at equal budget runs {', '.join(map(str, extra))} more, "
            "for the repertoire's evaluations"
        )
    return text


def default_out() -> Path:
    """``docs/study`` of the source tree (or the current folder when installed)."""
    root = Path(__file__).resolve().parents[2]
    return root / "docs" / "study" if (root / "docs").is_dir() else Path(os.getcwd())


def _span(low: int, high: int) -> str:
    """``"10"`` or ``"5-10"``: a count that may differ between settings."""
    return str(low) if low == high else f"{low}-{high}"
