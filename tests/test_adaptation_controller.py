"""Adaptation in the onboard controller: off by default, on by a call, fed by odometry."""

import math

import numpy as np
import pytest
from test_adaptation import turning_less
from test_nonfinite_outputs import standard_controller_file

from evorbc_ros.adaptation import AdaptationSettings
from evorbc_ros.adaptation.model import MATCHES
from evorbc_ros.adaptation.motion import extend_arc
from evorbc_ros.arbitration import Controller
from evorbc_ros.mapping import NO_PRIMITIVE

CYCLE_NS = 100_000_000


def inputs_held(controller, seed, stretches=30, length=12):
    """Sensor inputs in [0, 1], each held for ``length`` cycles (a primitive settles)."""
    rng = np.random.default_rng(seed)
    n = controller.spec.sensors.n_inputs
    return [row for row in rng.uniform(0, 1, (stretches, n)) for _ in range(length)]


def run(controller, inputs, factor=None):
    """Step through ``inputs``; with ``factor``, odometry of a robot turning that much."""
    rep = controller.repertoire
    x = y = h = 0.0
    out = []
    for t, row in enumerate(inputs):
        if factor is not None:
            controller.put_pose(t * CYCLE_NS, x, y, h)
        genes, diag = controller.step(row)
        out.append((genes.copy(), diag))
        index = int(diag[4])
        if factor is not None and index != NO_PRIMITIVE:
            damaged = turning_less((*rep.behaviour[index], rep.heading[index]), factor)
            dx, dy, dh = extend_arc(*damaged, rep.eval_time, 0.1)  # one settled cycle
            x, y = x + math.cos(h) * dx - math.sin(h) * dy, y + math.sin(h) * dx + math.cos(h) * dy
            h += dh
    return out


def same(a, b):
    return all(
        np.array_equal(ga, gb) and np.array_equal(np.array(da), np.array(db), equal_nan=True)
        for (ga, da), (gb, db) in zip(a, b, strict=True)
    )


@pytest.fixture(scope="module")
def inputs():
    return inputs_held(Controller(), 7)


def test_off_by_default_and_on_without_poses_chooses_as_evolved(inputs):
    off = Controller()
    assert off.adaptation is None and off.adaptation_state() == {}
    plain = run(off, inputs)
    on = Controller()
    on.enable_adaptation()
    assert same(run(on, inputs), plain)  # no odometry: no observation
    assert on.adaptation_state()["observations"] == 0
    # an intact robot's odometry (each primitive does what was recorded)
    intact = Controller()
    intact.enable_adaptation()
    run(intact, inputs, factor=1.0)
    assert intact.adaptation_state()["observations"] > 0
    assert intact.adaptation_state()["mean correction m"] < 1e-3


@pytest.mark.parametrize("match", MATCHES)
def test_observations_without_correction_choose_as_the_grid(match):
    """With corrections of 0 the choices are the grid's, exactly, with either matching.

    ``point`` matches at the grid cell's centre, where the grid holds the brute-force
    nearest; ``outcome`` finds the grid's own choice at distance 0.
    """
    off, on = Controller(), Controller()
    on.enable_adaptation(AdaptationSettings(match=match))
    model = on.adaptation.model
    for i in range(0, len(model), 3):
        model.observe(i, model.expected[i])  # what was expected: no correction
    assert model.used == 32 and not model.correction.any()
    rng = np.random.default_rng(8)
    rows = rng.uniform(0, 1, (400, off.spec.sensors.n_inputs))
    assert same(run(on, rows), run(off, rows))


@pytest.mark.parametrize("match", MATCHES)
def test_a_damaged_robot_is_corrected_and_reset_forgets(inputs, match):
    plain = run(Controller(), inputs)
    c = Controller()
    c.enable_adaptation(AdaptationSettings(match=match))
    damaged = run(c, inputs, factor=0.5)
    state = c.adaptation_state()
    assert state["observations"] >= 10
    assert state["mean heading correction rad"] > 0.05
    assert 0.0 <= state["uncertainty"] < 1.0
    assert not same(damaged, plain)  # the choices changed
    again = Controller()
    again.enable_adaptation(AdaptationSettings(match=match))
    assert same(run(again, inputs, factor=0.5), damaged)  # deterministic
    c.reset_adaptation()
    c.reset()
    assert c.adaptation_state()["observations"] == 0
    assert same(run(c, inputs), plain)
    c.disable_adaptation()
    assert c.adaptation is None


def test_a_standard_controller_cannot_adapt(tmp_path):
    _, path = standard_controller_file(tmp_path)
    with pytest.raises(ValueError, match="needs an EvoRBC controller"):
        Controller(str(path)).enable_adaptation()
