"""The study report's statistics: Holm's adjustment, the tests and the verdicts."""

import math

import numpy as np
import pytest
from scipy import stats

from offline_evolution.study.stats import (
    FAILS,
    HOLDS,
    INCONCLUSIVE,
    evaluate_claims,
    holm,
    kruskal_wallis,
    mann_whitney,
)


def test_holm_steps_down_and_keeps_the_input_order():
    # Sorted: 0.005 x 4 = 0.02, 0.01 x 3 = 0.03, 0.03 x 2 = 0.06, 0.04 x 1 -> max(0.06, 0.04).
    assert holm([0.01, 0.04, 0.03, 0.005]) == pytest.approx([0.03, 0.06, 0.06, 0.02])
    assert holm([0.5, 0.9]) == pytest.approx([1.0, 1.0])  # capped at 1
    got = holm([0.2, math.nan, 0.01])
    assert math.isnan(got[1]) and got[0] == pytest.approx(0.2) and got[2] == pytest.approx(0.02)


def test_mann_whitney_is_scipys_two_sided_test_with_a12():
    a, b = [1.2, 1.3, 1.25, 1.4, 1.1], [0.4, 0.5, 0.45, 1.15, 0.3]
    p, a12 = mann_whitney(a, b)
    assert p == pytest.approx(stats.mannwhitneyu(a, b, alternative="two-sided").pvalue)
    assert a12 == pytest.approx(24 / 25)  # a beats b in 24 of the 25 pairs
    assert mann_whitney([1.0, 1.0], [1.0, 1.0]) == (1.0, 0.5)
    assert all(math.isnan(v) for v in mann_whitney([1.0], [2.0, 3.0]))


def test_kruskal_wallis_matches_scipy():
    groups = [[1.0, 1.1, 1.2], [1.3, 1.4, 1.5], [0.2, 0.3, 0.1]]
    p, eps = kruskal_wallis(groups)
    h, p_scipy = stats.kruskal(*groups)
    assert p == pytest.approx(p_scipy) and eps == pytest.approx(h / 8)


def _samples():
    rng = np.random.default_rng(3)
    return [
        ({"robot": "a", "approach": "evorbc"}, 1.2 + 0.01 * rng.standard_normal(10)),
        ({"robot": "a", "approach": "standard"}, 0.5 + 0.01 * rng.standard_normal(10)),
        ({"robot": "b", "approach": "evorbc"}, 1.2 + 0.01 * rng.standard_normal(10)),
        ({"robot": "b", "approach": "standard"}, 1.2 + 0.01 * rng.standard_normal(10)),
    ]


@pytest.mark.parametrize(
    ("a", "b", "expect", "verdict"),
    [
        ("a", "a", "greater", HOLDS),  # evorbc clearly above standard on robot a
        ("a", "a", "same", FAILS),
        ("b", "b", "same", HOLDS),  # same distribution on robot b
        ("b", "b", "greater", INCONCLUSIVE),
        ("a", "a", "less", FAILS),
        ("a", "a", "not-less", HOLDS),
    ],
)
def test_verdicts_follow_the_adjusted_tests(a, b, expect, verdict):
    claim = {
        "claim": "c",
        "test": "mann-whitney",
        "a": {"robot": a, "approach": "evorbc"},
        "b": {"robot": b, "approach": "standard"},
        "expect": expect,
    }
    (result,) = evaluate_claims([claim], _samples())
    assert result.verdict == verdict


def test_a_family_shares_one_holm_adjustment():
    claims = [
        {"claim": f"c{r}", "test": "mann-whitney", "family": "f", "expect": "greater",
         "a": {"robot": r, "approach": "evorbc"}, "b": {"robot": r, "approach": "standard"}}
        for r in ("a", "b")
    ]  # fmt: skip
    results = evaluate_claims(claims, _samples())
    raw = [r.comparisons[0].p for r in results]
    assert [r.comparisons[0].p_adjusted for r in results] == pytest.approx(holm(raw))


def test_adjacent_pairs_and_best_and_correlation():
    samples = [
        ({"bin_size": b, "eval_time": t}, np.full(5, 1.0 + v) + np.arange(5) * 1e-3)
        for (b, t, v) in [(0.01, 1.0, 0.2), (0.04, 1.0, 0.1), (0.10, 1.0, -0.3), (0.01, 2.0, 0.3),
                          (0.04, 2.0, 0.4), (0.10, 2.0, 0.0)]
    ]  # fmt: skip
    adjacent, best_claim, wrong_best = evaluate_claims(
        [
            {"claim": "smaller bins", "test": "mann-whitney", "adjacent": "bin_size",
             "expect": "not-less"},
            {"claim": "best", "test": "best", "a": {"bin_size": 0.04, "eval_time": 2.0}},
            {"claim": "best", "test": "best", "a": {"bin_size": 0.01, "eval_time": 1.0}},
        ],
        samples,
    )  # fmt: skip
    labels = [c.label for c in adjacent.comparisons]
    assert labels == [
        "bin_size 0.01 vs 0.04 at eval_time 1.0",
        "bin_size 0.04 vs 0.1 at eval_time 1.0",
        "bin_size 0.01 vs 0.04 at eval_time 2.0",
        "bin_size 0.04 vs 0.1 at eval_time 2.0",
    ]
    assert adjacent.verdict == FAILS  # 1 cm is below 4 cm at 2 s
    assert best_claim.verdict == HOLDS
    assert wrong_best.verdict == FAILS
    assert "eval_time 2.0" in wrong_best.comparisons[0].note


def test_best_needs_significance_and_runs():
    """A setting that leads by noise, or has no runs, is inconclusive, not holds or fails."""
    rng = np.random.default_rng(5)
    noisy = [
        ({"bin_size": 0.04}, 1.20 + 0.1 * rng.standard_normal(5)),
        ({"bin_size": 0.02}, 1.19 + 0.1 * rng.standard_normal(5)),
        ({"bin_size": 0.10}, 0.50 + 0.1 * rng.standard_normal(5)),
    ]
    claims = [
        {"claim": "leads", "test": "best", "a": {"bin_size": 0.04}},
        {"claim": "second", "test": "best", "a": {"bin_size": 0.02}},
        {"claim": "worst", "test": "best", "a": {"bin_size": 0.10}},
        {"claim": "never run", "test": "best", "a": {"bin_size": 0.01}},
    ]
    leads, second, worst, never = evaluate_claims(claims, noisy)
    assert leads.verdict == INCONCLUSIVE and second.verdict == INCONCLUSIVE
    assert worst.verdict == FAILS  # the leader is far above it
    assert never.verdict == INCONCLUSIVE and never.comparisons[0].note == "no runs of this setting"
    top = leads if leads.comparisons[0].means[0] > second.comparisons[0].means[0] else second
    assert top.comparisons[0].note.startswith("the highest mean, not significantly above 1 of 2")
    assert worst.comparisons[0].note.endswith("is significantly above it")


def test_best_goes_by_ranks_against_every_other_setting():
    # "outlier" has the highest mean from one run alone; "steady" beats it in ranks.
    samples = [
        ({"s": "outlier"}, np.array([0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 9.0])),
        ({"s": "steady"}, np.array([1.0, 1.1, 1.2, 1.0, 1.1, 1.2, 1.0, 1.1, 1.2])),
        ({"s": "low"}, np.array([0.1, 0.2, 0.3, 0.1, 0.2, 0.3, 0.1, 0.2, 0.3])),
    ]
    claims = [{"claim": c, "test": "best", "a": {"s": c}} for c in ("outlier", "steady", "low")]
    outlier, steady, low = evaluate_claims(claims, samples)
    assert outlier.verdict == FAILS  # steady is significantly above it in ranks
    assert steady.verdict == INCONCLUSIVE  # above in ranks, but not the highest mean
    assert low.verdict == FAILS
    # Leading in mean and significantly above every other setting: holds.
    clean = [({"s": "a"}, np.array([2.0, 2.1, 2.2, 2.3, 2.4])), *samples[1:]]
    (a,) = evaluate_claims([{"claim": "a", "test": "best", "a": {"s": "a"}}], clean)
    assert a.verdict == HOLDS and "the weakest win: s steady" in a.comparisons[0].note


@pytest.mark.parametrize(("a12", "verdict"), [(0.71, INCONCLUSIVE), (0.29, INCONCLUSIVE)])
def test_the_large_effect_threshold_is_symmetric(a12, verdict):
    # 10 against 10 runs with U = 71 (or 29): A12 exactly 0.71 (0.29), not significant.
    a = np.arange(10, dtype=float)
    b = a - 2.5  # a beats b in 72 of the 100 pairs
    b[-1] = 7.5  # ... and in 71: a12 0.71
    samples = (
        [({"m": "a"}, a), ({"m": "b"}, b)] if a12 > 0.5 else [({"m": "a"}, b), ({"m": "b"}, a)]
    )
    claim = {"claim": "c", "test": "mann-whitney", "a": {"m": "a"}, "b": {"m": "b"},
             "expect": "same"}  # fmt: skip
    (result,) = evaluate_claims([claim], samples)
    assert result.comparisons[0].effect == pytest.approx(a12)
    assert result.comparisons[0].p > 0.05 and result.verdict == verdict


def test_same_with_a_large_unproven_effect_is_inconclusive():
    # 3 against 3 runs, all of a above all of b: A12 1.0, yet the exact p is 0.1.
    samples = [
        ({"mapping": "polar"}, np.array([1.30, 1.31, 1.32])),
        ({"mapping": "cartesian"}, np.array([1.20, 1.21, 1.22])),
    ]
    claim = {"claim": "c", "test": "mann-whitney", "a": {"mapping": "polar"},
             "b": {"mapping": "cartesian"}, "expect": "same"}  # fmt: skip
    (result,) = evaluate_claims([claim], samples)
    comp = result.comparisons[0]
    assert comp.p > 0.05 and comp.effect == 1.0
    assert result.verdict == INCONCLUSIVE


@pytest.mark.parametrize(
    ("first", "second", "verdict"),
    [
        ([1.20, 1.21, 1.22], [1.30, 1.31, 1.32], INCONCLUSIVE),  # lower in every pair, p 0.1
        ([1.30, 1.31, 1.32], [1.20, 1.21, 1.22], HOLDS),  # higher: never against the claim
        ([1.20, 1.31, 1.22], [1.30, 1.21, 1.32], HOLDS),  # mixed: A12 0.33, not large
    ],
)
def test_not_less_with_a_large_unproven_loss_is_inconclusive(first, second, verdict):
    samples = [({"b": 0.01}, np.array(first)), ({"b": 0.02}, np.array(second))]
    claim = {"claim": "smaller bins", "test": "mann-whitney", "adjacent": "b",
             "expect": "not-less"}  # fmt: skip
    (result,) = evaluate_claims([claim], samples)
    assert result.comparisons[0].p > 0.05
    assert result.verdict == verdict
