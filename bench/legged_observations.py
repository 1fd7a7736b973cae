"""Measure: do a legged robot's 0.1 s cycles give the settled-cycle rule usable observations?

Runs the shipped controller of ``--robot`` (default the hexapod), intact and without
adaptation, on a suite (default its training mazes; ``--generated N`` for generated ones)
and feeds each episode's poses and choices to the onboard
:class:`~evorbc_ros.adaptation.OnlineAdaptation` as the arbitrator node feeds it (pose at
each cycle's start, the primitive chosen then), without letting it choose: what the rule
would observe of the evolved behaviour (docs/design/adaptation.md, "Legged robots").

Prints, for the episodes: how often the controller switches primitive and how long it
holds one; the rule's tolerances; the share of held cycles (``k`` >= 2 of the same
primitive) the rule accepts and why the others fail (agreement with the cycle before,
too little translation); observations and distinct primitives observed per episode, with
the default (wheeled) settings and with the robot family's
(:func:`~evorbc_ros.adaptation.settings_for`); and how far a held cycle's motion, extended
to ``T`` (``adaptation.motion.extend_arc``), is from the primitive's recorded outcome,
against the same over ``L`` cycles after a run's first (``--runs``): whether longer
executions average the gait's oscillation out. For scale: the median distance from a
primitive to its nearest other one in the same metric.

With ``--settled-contexts C`` (> 0) it also computes the legged settled outcomes
(:func:`sim_bridge.legged.settled.context_outcomes`, ``C`` seeded contexts on flat ground)
of the primitives that ran long enough to be observed, and reports how far the same
executions are from them, and how far each context's own reading is from their mean (the
scatter of one observation on flat ground).

    python bench/legged_observations.py [--robot hexapod] [--starts 2] [--generated N]
        [--perturb SET] [--settled-contexts 4] [--out FILE.json]
"""

from __future__ import annotations

import argparse
import itertools
import json
from dataclasses import asdict

import numpy as np

from evorbc_ros.adaptation import AdaptationSettings, OnlineAdaptation, outcome_table, settings_for
from evorbc_ros.adaptation.motion import extend_arc, relative_motion
from evorbc_ros.adaptation.online import settings_arrays
from evorbc_ros.arbitration import robot_family
from evorbc_ros.mapping import NO_PRIMITIVE
from offline_evolution.reporters import Reporters
from offline_evolution.runs.evaluate import EvaluateRun, run_suites


def _extended(a, b, cycles: int, dt: float, horizon: float) -> np.ndarray:
    """The motion from pose ``a`` to pose ``b`` over ``cycles`` cycles, extended to ``T``."""
    return np.array(extend_arc(*relative_motion(*a, *b), cycles * dt, horizon))


def _distance(motion: np.ndarray, outcome: np.ndarray, weight: np.ndarray) -> float:
    """Outcome-matching distance: each of dx, dy, dheading over the repertoire's extent."""
    return float(np.sqrt((((motion - outcome) * weight) ** 2).sum()))


def _nearest(recorded: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """``(n,)`` each primitive's distance to its nearest other one (outcome-matching metric)."""
    d = np.sqrt((((recorded[:, None] - recorded[None, :]) * weight) ** 2).sum(axis=-1))
    np.fill_diagonal(d, np.inf)
    return d.min(axis=1)


def episode_figures(
    path, choice, recorded, weight, horizon, dt, settings, family_settings, runs_of, settled=None
) -> dict:
    """One episode's figures (see the module docstring)."""
    choice = choice[: len(path) - 1]  # a robot that fell stops its trace early
    online = OnlineAdaptation(recorded, horizon, settings)
    family = OnlineAdaptation(recorded, horizon, family_settings)
    pos_tol, head_tol = online.tolerance
    held = agree = moving = 0
    cycle_err, run_err = [], {k: [] for k in runs_of}
    # (error against recorded, against settled) of the executions whose primitive has both
    paired = {k: [] for k in runs_of}
    last, k_run, run_start = None, 0, 0
    for t, ran in enumerate(choice):
        for a in (online, family):
            a.put_pose(round(t * dt * 1e9), *map(float, path[t]))
            a.before_choice()
            a.after_choice(int(ran))
        k_run = k_run + 1 if t and ran == choice[t - 1] else 1
        if k_run == 1:
            run_start, last = t, None
        motion = _extended(path[t], path[t + 1], 1, dt, horizon)
        if ran != NO_PRIMITIVE and k_run >= 2:
            held += 1
            cycle_err.append(_distance(motion, recorded[ran], weight))
            if last is not None:
                moving += np.hypot(*motion[:2]) > pos_tol
                agree += (
                    np.hypot(*(motion[:2] - last[:2])) <= pos_tol
                    and abs(motion[2] - last[2]) <= head_tol
                )
        last = motion
        ends = t + 1 == len(choice) or choice[t + 1] != ran
        if ends and ran != NO_PRIMITIVE:
            n = t + 1 - run_start
            for k in runs_of:
                if n > k:  # k cycles after the run's first, as one execution of k cycles
                    a, b = path[run_start + 1], path[run_start + 1 + k]
                    m = _extended(a, b, k, dt, horizon)
                    run_err[k].append(_distance(m, recorded[ran], weight))
                    if settled is not None and int(ran) in settled:
                        paired[k].append((run_err[k][-1], _distance(m, settled[int(ran)], weight)))
    for a in (online, family):
        a.put_pose(round(len(choice) * dt * 1e9), *map(float, path[len(choice)]))
        a.before_choice()
    return {
        "cycles": len(choice),
        "switches": int(np.sum(choice[1:] != choice[:-1])),
        "held": held,
        "agree": int(agree),
        "moving": int(moving),
        "observations": online.model.observations,
        "observed": online.model.used,
        "family_observations": family.model.observations,
        "family_observed": family.model.used,
        "cycle_err": cycle_err,
        "run_err": run_err,
        "paired": paired,
    }


def observed_settled(runs, rep, family, contexts: int, weight) -> tuple[dict, list]:
    """Settled outcomes of the primitives run long enough to be observed, and their scatter.

    Returns ``({primitive: (3,) settled outcome}, [each context's distance from the mean])``.
    """
    from sim_bridge.legged.settled import context_outcomes

    need = 1 + family.settle_cycles + family.window - 1
    observed = set()
    for c in runs.suite.choices:
        edges = np.flatnonzero(np.r_[True, c[1:] != c[:-1], True])
        for a, b in itertools.pairwise(edges):
            if b - a >= need and c[a] >= 0:  # not NO_PRIMITIVE, nor NOT_RUN padding
                observed.add(int(c[a]))
    index = sorted(observed)
    samples = context_outcomes(
        runs.task.robot, rep.genes, rep.eval_time, family.settle_cycles, family.window,
        contexts, indices=index,
    )  # fmt: skip
    mean = samples.mean(axis=1)
    scatter = np.sqrt((((samples - mean[:, None]) * weight) ** 2).sum(axis=-1)).ravel()
    return dict(zip(index, mean, strict=True)), scatter.tolist()


def settled_figures(eps, runs_of, contexts: int, scatter, q) -> dict:
    """The same executions against the recorded and the settled outcomes (paired)."""
    out = {"contexts": contexts, "context_scatter_p50_p90": q(scatter), "runs": {}}
    for k in runs_of:
        pairs = np.array([p for e in eps for p in e["paired"][k]]).reshape(-1, 2)
        out["runs"][k] = {
            "n": len(pairs),
            "recorded_p50_p90": q(pairs[:, 0]),
            "settled_p50_p90": q(pairs[:, 1]),
            "settled_closer_pct": round(100 * float(np.mean(pairs[:, 1] < pairs[:, 0])), 1)
            if len(pairs)
            else None,
        }
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="hexapod")
    parser.add_argument("--starts", type=int, default=2)
    parser.add_argument("--generated", type=int, default=None)
    parser.add_argument("--perturb", default="none", help="a perturbation or damage set")
    parser.add_argument("--runs", type=int, nargs="+", default=[1, 2, 5, 10, 20])
    parser.add_argument("--settled-contexts", type=int, default=0, help="0: no settled outcomes")
    parser.add_argument("--out", help="write the figures as JSON")
    args = parser.parse_args()
    run = EvaluateRun(
        robot=args.robot, starts=args.starts, generated=args.generated, perturb=args.perturb
    )
    runs = run_suites(run, Reporters([]))
    rep, dt = runs.repertoire, runs.task.dt
    recorded = outcome_table(rep.behaviour, rep.heading)
    weight = 1.0 / (recorded.max(axis=0) - recorded.min(axis=0))
    settings = AdaptationSettings()
    conf, _ = settings_arrays(recorded, rep.eval_time, settings)
    family = settings_for(robot_family(args.robot))
    settled, scatter = None, None
    if args.settled_contexts > 0:
        settled, scatter = observed_settled(runs, rep, family, args.settled_contexts, weight)
    eps = [
        episode_figures(
            p, c, recorded, weight, rep.eval_time, dt, settings, family, args.runs, settled
        )
        for p, c in zip(runs.suite.paths, runs.suite.choices, strict=True)
    ]
    cycles = sum(e["cycles"] for e in eps)
    held = sum(e["held"] for e in eps)
    lengths = np.concatenate(
        [np.diff(np.flatnonzero(np.r_[True, c[1:] != c[:-1], True])) for c in runs.suite.choices]
    )
    cycle_err = np.concatenate([e["cycle_err"] for e in eps]) if held else np.zeros(1)

    def q(v):
        return [round(float(np.percentile(v, s)), 3) for s in (50, 90)] if len(v) else None

    out = {
        "robot": args.robot,
        "perturb": args.perturb,
        "episodes": len(eps),
        "cycles": cycles,
        "reached": sum(e.reached for e in runs.suite.episodes),
        "tolerance": {
            "position_m_over_T": round(float(conf[0]), 4),
            "heading_rad_over_T": round(float(conf[1]), 4),
        },
        "extent": [round(float(v), 3) for v in recorded.max(axis=0) - recorded.min(axis=0)],
        "switch_pct": round(100 * sum(e["switches"] for e in eps) / cycles, 1),
        "run_length_cycles": {
            "mean": round(float(lengths.mean()), 2),
            "share_of_runs_ge": {k: round(float(np.mean(lengths >= k)), 3) for k in args.runs},
        },
        "held_cycles_pct": round(100 * held / cycles, 1),
        "held_agree_pct": round(100 * sum(e["agree"] for e in eps) / max(held, 1), 1),
        "held_moving_pct": round(100 * sum(e["moving"] for e in eps) / max(held, 1), 1),
        "observations_per_episode": [e["observations"] for e in eps],
        "primitives_observed_per_episode": [e["observed"] for e in eps],
        "family_settings": asdict(family),
        "family_observations_per_episode": [e["family_observations"] for e in eps],
        "family_primitives_observed_per_episode": [e["family_observed"] for e in eps],
        "nearest_neighbour_distance_p50": round(float(np.median(_nearest(recorded, weight))), 3),
        "held_cycle_error_p50_p90": q(cycle_err),
        "run_error_p50_p90": {
            k: {
                "n": sum(len(e["run_err"][k]) for e in eps),
                "err": q(np.concatenate([e["run_err"][k] for e in eps])),
            }
            for k in args.runs
        },
    }
    if settled is not None:
        out["settled"] = settled_figures(eps, args.runs, args.settled_contexts, scatter, q)
    print(json.dumps(out, indent=1))
    if args.out:
        from evorbc_ros.atomic_io import atomic_write_text

        atomic_write_text(args.out, json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
