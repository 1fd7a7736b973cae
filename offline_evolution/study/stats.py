"""The paper's statistics on a study's results, and a verdict per claim.

The paper compares two samples with the two-sided Mann-Whitney U test and adjusts the
p-values of several comparisons on one set of results with the Holm-Bonferroni method
(its footnote 2); it compares the four robot types with the Kruskal-Wallis test. Tests
and correlations are scipy's; Holm's step-down adjustment is written here because scipy
has none (``scipy.stats.false_discovery_control`` offers Benjamini-Hochberg only). Effect
sizes are the Vargha-Delaney A12 (the probability that a run of the first setting beats a
run of the second, from U) for pairs and epsilon-squared for Kruskal-Wallis.

A claim's verdict, at ``ALPHA`` = 0.05 after adjustment:

* ``greater``: *holds* if the first setting is significantly higher, *does not hold* if
  significantly lower, else *inconclusive at this sample size*;
* ``same``: *holds* if no test finds a difference (how the paper supports such claims; a
  small sample cannot prove equality, which the report says) and no pairwise effect is
  large (A12 at least 0.71 or at most 0.29: Vargha and Delaney's threshold of a large
  effect), *inconclusive* if a large pairwise effect is not significant, else *does not
  hold*; Kruskal-Wallis and correlation claims have no such guard;
* ``not-less``: *does not hold* if the first setting is significantly lower, is
  *inconclusive* if it is lower by a large effect that is not significant (A12 at most
  0.29), else *holds*;
* ``best``: *holds* if the setting has the highest mean of all settings and is
  significantly above every other one (:func:`_best`), *does not hold* if another is
  significantly above it, else *inconclusive*.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import stats

ALPHA = 0.05
LARGE_A12 = 0.21  # |A12 - 0.5| of a large effect (A12 >= 0.71 or <= 0.29)
HOLDS, FAILS, INCONCLUSIVE = "holds", "does not hold", "inconclusive at this sample size"


@dataclass
class Comparison:
    """One test of one claim (a claim with ``adjacent`` or ``by`` has several)."""

    label: str  # e.g. "2ws-2: evorbc vs standard"
    test: str  # mann-whitney, kruskal-wallis, correlation, best
    p: float = math.nan  # raw p-value
    p_adjusted: float = math.nan  # Holm within the claim's family
    effect: float = math.nan  # A12, epsilon^2 or Pearson's r
    effect_name: str = ""
    sizes: tuple[int, ...] = ()
    means: tuple[float, ...] = ()
    note: str = ""
    outcome: str = ""  # a 'best' test's verdict, decided with its comparisons (_best)


@dataclass
class ClaimResult:
    """A claim of the paper, its comparisons and the verdict."""

    claim: str
    paper: str
    expect: str
    family: str
    comparisons: list[Comparison] = field(default_factory=list)
    verdict: str = INCONCLUSIVE


def holm(p_values: list[float]) -> list[float]:
    """Holm-Bonferroni adjusted p-values, in the input order (NaN stays NaN).

    The i-th smallest of m p-values is multiplied by (m - i), and each adjusted value is at
    least the one before it (step-down), capped at 1.
    """
    p = np.asarray(p_values, dtype=float)
    finite = np.flatnonzero(~np.isnan(p))
    out = np.full(p.shape, np.nan)
    m = len(finite)
    running = 0.0
    for rank, i in enumerate(finite[np.argsort(p[finite], kind="stable")]):
        running = max(running, min(1.0, (m - rank) * p[i]))
        out[i] = running
    return out.tolist()


def mann_whitney(a, b) -> tuple[float, float]:
    """Two-sided Mann-Whitney U: ``(p, A12)``; A12 > 0.5 when ``a`` tends to be higher."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    if len(a) < 2 or len(b) < 2:
        return math.nan, math.nan
    if np.ptp(np.concatenate([a, b])) == 0:
        return 1.0, 0.5  # all equal: no difference (scipy would warn and give NaN)
    u, p = stats.mannwhitneyu(a, b, alternative="two-sided")
    return float(p), float(u) / (len(a) * len(b))


def kruskal_wallis(groups: list) -> tuple[float, float]:
    """Kruskal-Wallis H test over ``groups``: ``(p, epsilon^2)``."""
    groups = [np.asarray(g, float) for g in groups if len(g) > 0]
    n = sum(len(g) for g in groups)
    if len(groups) < 2 or any(len(g) < 2 for g in groups):
        return math.nan, math.nan
    if np.ptp(np.concatenate(groups)) == 0:
        return 1.0, 0.0
    h, p = stats.kruskal(*groups)
    return float(p), float(h) / (n - 1)


def select(values: dict, selector: dict) -> bool:
    """True if a setting's ``values`` match every key of ``selector``."""
    return all(values.get(k) == v for k, v in selector.items())


def evaluate_claims(
    claims: list[dict], samples: list[tuple[dict, np.ndarray]]
) -> list[ClaimResult]:
    """Test every claim of a study on its samples.

    Args:
        claims: the study file's ``compare`` entries.
        samples: per setting, its values and its runs' best fitness ``(n,)``.

    Returns:
        One :class:`ClaimResult` per claim, with Holm-adjusted p-values within families.
    """
    results = [_evaluate(c, samples) for c in claims]
    families: dict[str, list[Comparison]] = {}
    for r in results:
        for c in r.comparisons:
            if c.test != "best":
                families.setdefault(r.family or r.claim, []).append(c)
    for comps in families.values():
        for c, adj in zip(comps, holm([c.p for c in comps]), strict=True):
            c.p_adjusted = adj
    for r in results:
        r.verdict = verdict(r)
    return results


def _pooled(samples, selector) -> np.ndarray:
    parts = [s for v, s in samples if select(v, selector)]
    return np.concatenate(parts) if parts else np.empty(0)


def _label(selector: dict) -> str:
    return ", ".join(f"{k} {v}" for k, v in selector.items())


def _evaluate(claim: dict, samples) -> ClaimResult:
    result = ClaimResult(
        claim=str(claim.get("claim", "")),
        paper=str(claim.get("paper", "")),
        expect=str(claim.get("expect", "")),
        family=str(claim.get("family", "")),
    )
    test = claim.get("test")
    if test == "mann-whitney":
        pairs = _pairs(claim, samples)
        for label, a, b in pairs:
            p, a12 = mann_whitney(a, b)
            result.comparisons.append(
                Comparison(
                    label, test, p, effect=a12, effect_name="A12", sizes=(len(a), len(b)),
                    means=(_mean(a), _mean(b)),
                )
            )  # fmt: skip
    elif test == "kruskal-wallis":
        by = claim["by"]
        chosen = [(v, s) for v, s in samples if select(v, claim.get("groups", {}))]
        keys = sorted({v[by] for v, _ in chosen}, key=str)
        groups = [_pooled(chosen, {by: k}) for k in keys]
        p, eps = kruskal_wallis(groups)
        result.comparisons.append(
            Comparison(
                f"{by}: {', '.join(map(str, keys))}", test, p, effect=eps,
                effect_name="epsilon^2", sizes=tuple(map(len, groups)),
                means=tuple(map(_mean, groups)),
            )
        )  # fmt: skip
    elif test == "correlation":
        along, by = claim["along"], claim["by"]
        for key in sorted({v[by] for v, _ in samples}, key=_sort_key):
            xs, ys = [], []
            for v, s in samples:
                if v.get(by) == key:
                    xs += [v[along]] * len(s)
                    ys += list(s)
            comp = Comparison(f"{by} {key}: fitness against {along}", test, sizes=(len(ys),))
            if len(set(xs)) >= 3 and np.ptp(ys) > 0:
                r, p = stats.pearsonr(xs, ys)
                comp.p, comp.effect, comp.effect_name = float(p), float(r), "Pearson r"
            else:
                comp.note = "fewer than three values or no spread"
            result.comparisons.append(comp)
    elif test == "best":
        result.comparisons.append(_best(claim["a"], samples))
    else:
        raise ValueError(f"unknown test {test!r}")
    return result


def _best(target: dict, samples) -> Comparison:
    """Whether ``target`` beats every other setting, tested against each of them.

    The claim *holds* if the target has the highest mean and is significantly above every
    other setting (two-sided Mann-Whitney, A12 above 0.5, each test unadjusted: all must
    pass, so no adjustment is due); it *does not hold* if some setting is significantly
    above it; else it is *inconclusive*. The comparison shown is the deciding one: the
    weakest of the wins, the strongest of the losses, or, if neither decides, the leader
    (the runner-up if the target leads); ``means`` are the target's and that setting's.
    """
    own = _pooled(samples, target)
    if not len(own):
        return Comparison(
            _label(target), "best", sizes=(0,), note="no runs of this setting", outcome=INCONCLUSIVE
        )
    # Each other group of the target's keys once (settings that share them are pooled).
    groups = {
        tuple((k, v[k]) for k in target) for v, s in samples if len(s) and not select(v, target)
    }
    others = []
    for group in sorted(groups, key=str):
        pooled = _pooled(samples, dict(group))
        p, a12 = mann_whitney(own, pooled)
        others.append((_mean(pooled), _label(dict(group)), p, a12))
    if not others:
        return Comparison(
            _label(target), "best", sizes=(len(own),), note="no other setting",
            outcome=INCONCLUSIVE,
        )  # fmt: skip
    others.sort(key=lambda o: -o[0])
    leads = _mean(own) >= others[0][0]
    above = [o for o in others if o[2] < ALPHA and o[3] < 0.5]
    beaten = [o for o in others if o[2] < ALPHA and o[3] > 0.5]
    if above:
        outcome, (m, label, p, a12) = FAILS, min(above, key=lambda o: o[2])
        note = f"{label} ({m:.3f}) is significantly above it"
    elif leads and len(beaten) == len(others):
        outcome, (m, label, p, a12) = HOLDS, max(others, key=lambda o: o[2])
        note = (
            f"the highest mean, significantly above every other setting; the weakest win: {label}"
        )
    else:
        outcome, (m, label, p, a12) = INCONCLUSIVE, others[0]
        unproven = sum(1 for o in others if o not in beaten)
        note = (
            f"the highest mean, not significantly above {unproven} of {len(others)} settings; "
            f"the runner-up {m:.3f} ({label})"
            if leads
            else f"the highest mean is {m:.3f} ({label}), not significantly above it"
        )
    return Comparison(
        _label(target), "best", p, effect=a12, effect_name="A12", sizes=(len(own),),
        means=(_mean(own), m), note=note, outcome=outcome,
    )  # fmt: skip


def _pairs(claim: dict, samples) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """``(label, a, b)`` samples of a Mann-Whitney claim (``a``/``b`` or ``adjacent``)."""
    key = claim.get("adjacent")
    if not key:
        a, b = claim["a"], claim["b"]
        return [(f"{_label(a)} vs {_label(b)}", _pooled(samples, a), _pooled(samples, b))]
    # Neighbouring values of `key` (smaller first) with every other key equal.
    out = []
    others = sorted({tuple(sorted((k, v) for k, v in s.items() if k != key)) for s, _ in samples})
    for rest in others:
        fixed = dict(rest)
        values = sorted({v[key] for v, _ in samples if select(v, fixed)}, key=_sort_key)
        for small, large in itertools.pairwise(values):
            a = _pooled(samples, {**fixed, key: small})
            b = _pooled(samples, {**fixed, key: large})
            shown = {k: v for k, v in fixed.items() if k in _grid_keys(samples)}
            where = f" at {_label(shown)}" if shown else ""
            out.append((f"{key} {small} vs {large}{where}", a, b))
    return out


def _grid_keys(samples) -> set:
    """Keys whose values differ between settings."""
    keys = set().union(*(v for v, _ in samples))
    return {k for k in keys if len({str(v.get(k)) for v, _ in samples}) > 1}


def _sort_key(value):
    return (0, value) if isinstance(value, (int, float)) else (1, str(value))


def _mean(x) -> float:
    return float(np.mean(x)) if len(x) else math.nan


def verdict(result: ClaimResult) -> str:
    """The claim's verdict from its comparisons (see the module docstring)."""
    comps = result.comparisons
    if result.expect == "best" or (comps and comps[0].test == "best"):
        return comps[0].outcome or INCONCLUSIVE
    tested = [c for c in comps if not math.isnan(c.p_adjusted)]
    if not tested:
        return INCONCLUSIVE
    significant = [c for c in tested if c.p_adjusted < ALPHA]
    if result.expect == "same":
        if significant:
            return FAILS
        return INCONCLUSIVE if any(_large(c) for c in tested) else HOLDS
    if result.expect == "not-less":
        if any(c.effect < 0.5 for c in significant):
            return FAILS
        # A first setting that loses (almost) every pair is not shown "similar" by a test
        # too weak to see it, as for ``same``.
        return INCONCLUSIVE if any(_large(c) and c.effect < 0.5 for c in tested) else HOLDS
    if result.expect in ("greater", "less"):
        want_high = result.expect == "greater"
        if any((c.effect < 0.5) == want_high for c in significant):
            return FAILS
        if len(significant) == len(comps):
            return HOLDS
        return INCONCLUSIVE
    if result.expect == "different":
        return HOLDS if significant else INCONCLUSIVE
    raise ValueError(f"unknown expectation {result.expect!r}")


def _large(c: Comparison) -> bool:
    """A pairwise comparison with a large effect (A12 at least 0.71 or at most 0.29)."""
    # 1e-9: an A12 of exactly 0.71 (possible with 10 or 30 runs) is large, as 0.29 is.
    return c.effect_name == "A12" and abs(c.effect - 0.5) >= LARGE_A12 - 1e-9


def summary_row(values: dict[str, Any], keys: list[str]) -> str:
    """A setting's name from its grid keys."""
    return ", ".join(f"{values[k]}" for k in keys)
