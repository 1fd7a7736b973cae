"""The executor's safety logic without ROS: what is stale, and what is commanded."""

import numpy as np
import pytest

from evorbc_ros.executor import PrimitiveExecutor
from evorbc_ros.laser import InputError
from evorbc_ros.robots.four_ws import FourWSGeometry
from evorbc_ros.robots.registry import robot_type


def executor():
    return PrimitiveExecutor(robot_type("4ws-5"), FourWSGeometry(), ["rf", "goal"], 0.3)


def test_inputs_arriving_in_any_order_at_start_up_are_not_stale():
    ex = executor()
    assert ex.command(0.0).stopped and ex.command(0.0).reason == "no primitive yet"
    ex.on_input("rf", 0.0)
    ex.on_primitive([1, 0, 0, 0, 0], 0.0)  # the goal reading has not arrived yet
    assert not ex.command(0.0).stopped
    assert ex.stale(0.3) == []  # exactly 0.3 s: not stale
    assert ex.stale(0.31) == ["primitive", "rf", "goal"]


def test_a_silent_input_stops_the_robot_with_the_steering_held():
    ex = executor()
    for t in (0.0, 0.1, 0.2):
        ex.on_input("rf", t)
        ex.on_input("goal", t)
        ex.on_primitive([1.0, 0.5, 0.5, -0.5, -0.5], t)
    running = ex.command(0.2)
    assert running.speed == pytest.approx(0.2) and not running.stopped
    ex.on_input("goal", 0.6)
    ex.on_primitive([1.0, 0.5, 0.5, -0.5, -0.5], 0.6)
    stopped = ex.command(0.6)
    assert stopped.stopped and stopped.speed == 0.0 and "rf" in stopped.reason
    np.testing.assert_array_equal(stopped.steering, running.steering)
    ex.on_input("rf", 0.6)
    assert not ex.command(0.6).stopped


@pytest.mark.parametrize("genes", [[1, 0, 0, 0], [1, 0, 0, 0, np.nan], [1, 0, 0, 0, 1.5]])
def test_bad_primitives_are_refused(genes):
    with pytest.raises(InputError):
        executor().on_primitive(genes, 0.0)


def test_a_clock_that_goes_back_forgets_everything_and_stops_the_robot():
    # A restarted /clock or a looped bag: ages would be negative and never stale.
    ex = executor()
    for name in ("rf", "goal"):
        ex.on_input(name, 10.0)
    ex.on_primitive([1.0, 0.5, 0.5, -0.5, -0.5], 10.0)
    assert not ex.command(10.0).stopped
    back = ex.command(1.0)
    assert back.stopped and "clock went back" in back.reason and back.speed == 0.0
    ex.on_input("rf", 1.1)
    ex.on_input("goal", 1.1)
    assert ex.command(1.1).reason == "no primitive yet"  # the old primitive is forgotten
    ex.on_primitive([1.0, 0.5, 0.5, -0.5, -0.5], 1.2)
    assert not ex.command(1.2).stopped
    ex.on_input("rf", 0.5)  # an input stamped before the others: a reset as well
    assert ex.command(0.5).reason == "no primitive yet"


def test_the_hexapod_executor_sends_nothing_before_its_first_primitive():
    from evorbc_ros.hexapod_executor import HexapodExecutor

    ex = HexapodExecutor(["rf"], stale_timeout=0.3)
    ex.on_input("rf", 0.0)
    first = ex.command(0.0)
    # No made-up pose: a real robot would jerk every joint to it from wherever it stands.
    assert first.stopped and first.positions.shape == (0, 18)
    ex.on_primitive(np.linspace(-1, 1, 37), 0.1)
    walking = ex.command(0.1)
    assert not walking.stopped and len(walking.positions) == 15
    # The clock goes back: the gait restarts with the next primitive, and meanwhile the
    # legs hold the point they were tracking.
    held = ex.command(0.05)
    assert held.stopped and "clock went back" in held.reason
    np.testing.assert_array_equal(held.positions, walking.positions[:1])
    assert ex.gait_start is None
