"""Quality metrics on analytic arcs and lines, forward and backward (docs/design.md section 3)."""

import math

import numpy as np
import pytest

from offline_evolution.quality import METRICS, quality_metric, wrap_angle
from sim_bridge.robots.base import PrimitiveOutcome


def arc(phi, radius=0.2, backward=False, right=False, tilt=None):
    """End of an arc of angle phi (rad) on the circle tangent to +x at the origin."""
    x, y, heading = radius * math.sin(phi), radius * (1 - math.cos(phi)), phi
    if backward:
        x, heading = -x, -heading
    if right:
        y, heading = -y, -heading
    return PrimitiveOutcome(
        x=np.array([x]),
        y=np.array([y]),
        heading=np.array([heading]),
        path=np.array([radius * phi]),
        max_tilt=None if tilt is None else np.array([tilt]),
    )


def line(distance, bearing, heading):
    return PrimitiveOutcome(
        x=np.array([distance * math.cos(bearing)]),
        y=np.array([distance * math.sin(bearing)]),
        heading=np.array([heading]),
        path=np.array([abs(distance)]),
    )


ARC_ANGLES = [0.1, 0.8, 1.5, 2.5, 3.6, 4.7, 6.0]


@pytest.mark.parametrize("phi", ARC_ANGLES)
@pytest.mark.parametrize("backward", [False, True])
@pytest.mark.parametrize("right", [False, True])
def test_circular_is_one_on_every_circular_arc(phi, backward, right):
    o = arc(phi, backward=backward, right=right)
    assert quality_metric("circular")(o)[0] == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("error", [0.3, -1.0, math.pi / 2, 3.0])
def test_circular_falls_linearly_with_heading_error(error):
    o = arc(1.2)
    o = PrimitiveOutcome(o.x, o.y, o.heading + error, o.path)
    assert quality_metric("circular")(o)[0] == pytest.approx(1 - abs(error) / math.pi)


def test_circular_is_blind_to_full_turns_of_heading():
    o = arc(0.9)
    spun = PrimitiveOutcome(o.x, o.y, o.heading + 4 * math.pi, o.path)
    assert quality_metric("circular")(spun)[0] == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("bearing", [0.0, 0.5, -1.2, 1.5])
@pytest.mark.parametrize("metric", ["radial", "distance"])
def test_straight_forward_lines_score_one(bearing, metric):
    assert quality_metric(metric)(line(0.3, bearing, bearing))[0] == pytest.approx(1.0)


@pytest.mark.parametrize("bearing", [0.3, -0.6])
def test_radial_wants_the_robot_to_face_forward_when_reversing(bearing):
    # Reversing in a straight line to (-0.3 cos b, -0.3 sin b) keeps heading b.
    o = line(-0.3, bearing, bearing)
    assert o.x[0] < 0
    assert quality_metric("radial")(o)[0] == pytest.approx(1.0)
    turned = line(-0.3, bearing, bearing + math.pi)
    assert quality_metric("radial")(turned)[0] == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("phi", [0.4, 1.0, 2.0])
@pytest.mark.parametrize("backward", [False, True])
def test_radial_on_arcs_penalises_half_the_turn(phi, backward):
    # The bearing of an arc's end point is phi / 2 (forward) or -phi/2 + pi (backward); the
    # heading is +-phi, so the heading error is phi / 2 either way.
    o = arc(phi, backward=backward)
    assert quality_metric("radial")(o)[0] == pytest.approx(1 - (phi / 2) / math.pi)


@pytest.mark.parametrize("phi", [0.4, 1.0, 3.0])
@pytest.mark.parametrize("backward", [False, True])
def test_distance_is_chord_over_arc_length(phi, backward):
    expected = 2 * math.sin(phi / 2) / phi
    assert quality_metric("distance")(arc(phi, backward=backward))[0] == pytest.approx(expected)


def test_distance_of_a_robot_that_went_nowhere_is_zero():
    o = PrimitiveOutcome(np.zeros(1), np.zeros(1), np.zeros(1), np.zeros(1))
    assert quality_metric("distance")(o)[0] == 0.0


def test_combinations_are_sums():
    o = arc(1.3, backward=True)
    for combo, parts in [
        ("distance+circular", ("distance", "circular")),
        ("distance+radial", ("distance", "radial")),
    ]:
        expected = sum(quality_metric(p)(o)[0] for p in parts)
        assert quality_metric(combo)(o)[0] == pytest.approx(expected)
        assert METRICS[combo][1] == 2.0


@pytest.mark.parametrize(("tilt_deg", "expected"), [(0, 2.0), (9, 1.8), (45, 1.0)])
def test_circular_tilt_adds_the_stability_term(tilt_deg, expected):
    o = arc(1.0, tilt=math.radians(tilt_deg))
    assert quality_metric("circular+tilt")(o)[0] == pytest.approx(expected)


def test_circular_tilt_discards_primitives_that_tilt_past_45_degrees():
    o = arc(1.0, tilt=math.radians(45.5))
    assert np.isnan(quality_metric("circular+tilt")(o)[0])


def test_wrap_angle_range_is_half_open():
    np.testing.assert_allclose(
        wrap_angle(np.array([math.pi, -math.pi, 3 * math.pi, 0.5])),
        [math.pi, math.pi, math.pi, 0.5],
    )


def test_unknown_metric_names_the_known_ones():
    with pytest.raises(KeyError, match="circular"):
        quality_metric("curly")
