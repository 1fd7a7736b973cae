"""The corrected outcome model (docs/design.md section 24): prior, learning, determinism."""

import math

import numba as nb
import numpy as np
import pytest

from evorbc_ros.adaptation import (
    AdaptationSettings,
    OnlineAdaptation,
    OutcomeModel,
    gp,
    outcome_table,
)
from evorbc_ros.adaptation.motion import compose, extend_arc, relative_motion
from evorbc_ros.defaults import default_repertoire
from evorbc_ros.repertoire import Repertoire

T = 2.0


@pytest.fixture(scope="module")
def recorded():
    rep = Repertoire.load(default_repertoire("4ws-5"))
    return outcome_table(rep.behaviour, rep.heading)


def turning_less(outcome, factor):
    """The outcome over T of the same arc (speed along it kept) turning ``factor`` as fast."""
    dx, dy, dh = outcome
    chord = math.hypot(dx, dy)
    half = 0.5 * dh
    length = chord if half == 0 else chord * half / math.sin(half)  # arc length
    start = math.atan2(dy, dx) - half  # initial direction of travel
    h = factor * dh
    sinc = 1.0 if h == 0 else math.sin(0.5 * h) / (0.5 * h)
    return np.array(
        [length * sinc * math.cos(start + 0.5 * h), length * sinc * math.sin(start + 0.5 * h), h]
    )


def feed(model, recorded, rows, factor=0.8):
    for i in rows:
        model.observe(int(i), turning_less(recorded[i], factor))


def test_no_observation_is_the_prior_exactly(recorded):
    model = OutcomeModel(recorded, AdaptationSettings())
    assert np.array_equal(model.corrected, recorded)
    assert model.uncertainty(3) == 1.0
    for x, y in [(0.1, 0.0), (-0.2, 0.1), (0.0, 0.0)]:
        d = np.hypot(recorded[:, 0] - x, recorded[:, 1] - y)
        assert model.nearest(x, y) == int(np.argmin(d))


def test_posterior_mean_is_the_gaussian_process(recorded):
    model = OutcomeModel(recorded, AdaptationSettings(capacity=16))
    rows = np.random.default_rng(3).choice(len(recorded), 40, replace=False)
    feed(model, recorded, rows)
    assert model.used == 16 and model.observations == 40
    slots = model.slots
    kzz = model.kzx[:, slots] + 0.05 * np.eye(16)
    want = recorded + (np.linalg.solve(kzz, model.residual).T @ model.kzx).T
    np.testing.assert_allclose(model.corrected, want, atol=1e-12)
    # the ring holds the last 16 distinct primitives, with their latest residuals
    assert sorted(slots) == sorted(rows[-16:])
    i = int(slots[0])
    k = model.kzx[:, i]
    assert model.uncertainty(i) == pytest.approx(1.0 - k @ np.linalg.solve(kzz, k), abs=1e-12)
    assert model.uncertainty(i) < 0.1


def test_deterministic_and_reset(recorded):
    rows = np.random.default_rng(4).integers(0, len(recorded), 50)
    a = OutcomeModel(recorded, AdaptationSettings())
    b = OutcomeModel(recorded, AdaptationSettings())
    feed(a, recorded, rows)
    feed(b, recorded, rows)
    assert np.array_equal(a.corrected, b.corrected)
    assert np.array_equal(a.alpha, b.alpha)
    a.reset()
    assert np.array_equal(a.corrected, recorded) and a.used == 0 and a.observations == 0
    assert a.uncertainty(int(rows[0])) == 1.0
    feed(a, recorded, rows)  # after a reset, as from new
    assert np.array_equal(a.corrected, b.corrected)


def test_compiled_functions_give_the_same_bits(recorded):
    rows = np.random.default_rng(5).integers(0, len(recorded), 45)
    plain = OutcomeModel(recorded, AdaptationSettings())
    jitted = OutcomeModel(recorded, AdaptationSettings(), functions=gp.compiled(nb.njit))
    feed(plain, recorded, rows)
    feed(jitted, recorded, rows)
    assert np.array_equal(plain.corrected, jitted.corrected)
    assert plain.uncertainty(int(rows[-1])) == jitted.uncertainty(int(rows[-1]))
    assert plain.nearest(0.1, 0.05) == jitted.nearest(0.1, 0.05)
    assert plain.nearest_outcome(7) == jitted.nearest_outcome(7)


def test_repeated_observations_are_averaged_with_the_noise_over_their_number(recorded):
    """``average`` > 1: a slot holds the mean of its primitive's readings, noise / hits."""
    rng = np.random.default_rng(8)
    i, j = 11, 40
    readings = [recorded[i] + rng.normal(0.0, 0.02, 3) for _ in range(6)]
    for average, kept in ((4, 4), (1, 1)):
        model = OutcomeModel(recorded, AdaptationSettings(average=average))
        for r in readings[:3]:
            model.observe(i, r)
        model.observe(j, recorded[j] + 0.01)
        s = int(np.flatnonzero(model.slots == i)[0])
        want = np.mean(readings[3 - min(3, kept) : 3], axis=0) - recorded[i]
        np.testing.assert_allclose(model.residual[s], want, atol=1e-15)
        assert model.counts[gp.HITS + s] == min(3, kept)
        # the GP sees the slot's noise over its count
        m = model.used
        kzz = model.kzx[:m][:, model.slots[:m]] + 0.05 * np.diag(
            1.0 / model.counts[gp.HITS : gp.HITS + m]
        )
        want = recorded + (np.linalg.solve(kzz, model.residual[:m]).T @ model.kzx[:m]).T
        np.testing.assert_allclose(model.corrected, want, atol=1e-12)
    # past ``average`` the mean is exponential (weight 1/average on the newest)
    model = OutcomeModel(recorded, AdaptationSettings(average=2))
    for r in readings:
        model.observe(i, r)
    want = readings[0] - recorded[i]
    for r in readings[1:]:
        want = want + (r - recorded[i] - want) / 2
    np.testing.assert_allclose(model.residual[0], want, atol=1e-15)
    # a reset forgets the counts and keeps the setting; a slot taken anew starts at 1
    model.reset()
    assert model.counts[gp.AVERAGE] == 2 and not model.counts[gp.HITS :].any()
    model.observe(i, readings[5])
    np.testing.assert_array_equal(model.residual[0], readings[5] - recorded[i])
    # plain and compiled give the same bits
    jitted = OutcomeModel(recorded, AdaptationSettings(average=3), functions=gp.compiled(nb.njit))
    plain = OutcomeModel(recorded, AdaptationSettings(average=3))
    for k, r in enumerate(readings * 2):
        for m in (plain, jitted):
            m.observe((i, j, i, 7)[k % 4], r)
    assert np.array_equal(plain.corrected, jitted.corrected)


def test_turning_twenty_percent_less_is_learned(recorded):
    """Observed primitives teach the model about the others, and the choices improve."""
    rng = np.random.default_rng(6)
    order = rng.permutation(len(recorded))
    seen, unseen = order[:32], order[32:]
    model = OutcomeModel(recorded, AdaptationSettings())
    feed(model, recorded, seen)
    truth = np.array([turning_less(o, 0.8) for o in recorded])
    before = np.abs(recorded[unseen, 2] - truth[unseen, 2]).mean()
    after = np.abs(model.corrected[unseen, 2] - truth[unseen, 2]).mean()
    assert after < 0.5 * before
    # Targets in the behaviour space: what the chosen primitive really does lands nearer.
    targets = rng.uniform(-0.3, 0.3, (300, 2))
    changed = 0
    err_prior, err_adapted = [], []
    for x, y in targets:
        prior = int(np.argmin(np.hypot(recorded[:, 0] - x, recorded[:, 1] - y)))
        adapted = model.nearest(x, y)
        changed += adapted != prior
        err_prior.append(math.hypot(*(truth[prior, :2] - (x, y))))
        err_adapted.append(math.hypot(*(truth[adapted, :2] - (x, y))))
    assert changed > 30
    assert np.mean(err_adapted) < 0.8 * np.mean(err_prior)


def test_arc_extension_is_exact_for_a_constant_twist():
    v, w, tau = 0.2, 0.9, 0.1

    def arc(t):
        return (v * math.sin(w * t) / w, v * (1 - math.cos(w * t)) / w, w * t)

    np.testing.assert_allclose(extend_arc(*arc(tau), tau, T), arc(T), atol=1e-14)
    np.testing.assert_allclose(extend_arc(0.02, 0.0, 0.0, 0.1, T), (0.4, 0.0, 0.0), atol=1e-15)
    # three cycles composed are one longer arc
    three = compose(*compose(*arc(tau), *arc(tau)), *arc(tau))
    np.testing.assert_allclose(three, arc(3 * tau), atol=1e-15)
    # a pose pair in a rotated world frame gives the same body-frame motion
    x, y, h = 1.0, -2.0, 2.5
    dx, dy, dh = arc(tau)
    x1 = x + math.cos(h) * dx - math.sin(h) * dy
    y1 = y + math.sin(h) * dx + math.cos(h) * dy
    np.testing.assert_allclose(relative_motion(x, y, h, x1, y1, h + dh - 2 * math.pi), arc(tau))


def drive(adapt, choices, twist, t0=0, pose=(0.0, 0.0, 0.0)):
    """Run ``choices`` (one per 0.1 s cycle) with each cycle moving ``twist(choice)``."""
    x, y, h = pose
    stamp = t0
    for index in choices:
        adapt.put_pose(stamp, x, y, h)
        adapt.before_choice()
        adapt.after_choice(index)
        dx, dy, dh = twist(index)
        x, y = x + math.cos(h) * dx - math.sin(h) * dy, y + math.sin(h) * dx + math.cos(h) * dy
        h += dh
        stamp += 100_000_000
    return stamp, (x, y, h)


def test_only_settled_cycles_are_observed(recorded):
    settings = AdaptationSettings(settle_cycles=3, window=4)
    adapt = OnlineAdaptation(recorded, T, settings)
    moves = {i: (0.01 * (1 + i % 3), 0.001 * (i % 5), 0.02 * (i % 7 - 3)) for i in range(50)}
    # switching every cycle, or holding for no more than the settling cycles: nothing
    drive(adapt, [1, 2, 3, 4, 1, 1, 1, 2, 2, 2, 5], moves.__getitem__)
    assert adapt.model.observations == 0
    assert np.array_equal(adapt.model.corrected, recorded)
    # held for 3 + 4 cycles: one observation of 4 settled cycles, when the window fills
    drive(adapt, [7] * 8, moves.__getitem__, t0=10**10)
    assert adapt.model.observations == 1 and adapt.model.slots[0] == 7
    want = extend_arc(*moves[7], 0.1, T)
    np.testing.assert_allclose(adapt.model.residual[0], np.subtract(want, recorded[7]), atol=1e-12)
    # a stamp that does not advance breaks the run: no observation from it
    adapt.reset()
    for _ in range(10):
        adapt.put_pose(5, 0.0, 0.0, 0.0)
        adapt.before_choice()
        adapt.after_choice(9)
    assert adapt.model.observations == 0


def test_settings_are_checked():
    with pytest.raises(ValueError, match="adaptation capacity must be"):
        AdaptationSettings(capacity=0)
    with pytest.raises(ValueError, match="adaptation noise must be"):
        AdaptationSettings(noise=0.0)
    with pytest.raises(ValueError, match="adaptation match must be one of outcome, point"):
        AdaptationSettings(match="nearest")
    with pytest.raises(ValueError, match="adaptation average must be between 1 and 1000"):
        AdaptationSettings(average=0)


def test_remainder_is_math_remainder_plain_and_compiled():
    from evorbc_ros.adaptation.motion import remainder

    jitted = nb.njit(remainder)
    y = 2.0 * math.pi
    xs = np.random.default_rng(0).uniform(-40.0, 40.0, 20_000).tolist()
    xs += [0.0, -0.0, math.pi, -math.pi, 3 * math.pi, 0.5 * y, 1.5 * y, -1.5 * y, 2.5 * y, y]
    for x in xs:
        want = np.float64(math.remainder(x, y)).tobytes()
        assert np.float64(remainder(x, y)).tobytes() == want
        assert np.float64(jitted(x, y)).tobytes() == want


def test_compiled_settled_cycle_rule_gives_the_same_bits(recorded):
    from evorbc_ros.adaptation import cycles

    rng = np.random.default_rng(3)
    n = len(recorded)
    runs = [
        OnlineAdaptation(recorded, T, AdaptationSettings(window=3)),
        OnlineAdaptation(
            recorded, T, AdaptationSettings(window=3), functions=cycles.compiled(nb.njit)
        ),
    ]
    x = y = h = 0.0
    index = left = 0
    for t in range(1500):
        if left == 0:
            index, left = int(rng.integers(n)), int(rng.integers(1, 12))
        left -= 1
        chosen = []
        for a in runs:
            a.put_pose(t * 100_000_000, x, y, h)
            a.before_choice()
            chosen.append(a.choose(0.0, 0.0, index))
            a.after_choice(chosen[-1])
        assert chosen[0] == chosen[1]
        dx, dy, dh = recorded[chosen[0]] * (0.04 if chosen[0] % 2 else 0.06)
        x, y = x + math.cos(h) * dx - math.sin(h) * dy, y + math.sin(h) * dx + math.cos(h) * dy
        h += dh
    assert runs[0].model.observations > 10
    assert runs[0].model.corrected.tobytes() == runs[1].model.corrected.tobytes()
    assert runs[0].ints.tolist() == runs[1].ints.tolist()
    assert runs[0].floats.tobytes() == runs[1].floats.tobytes()
