"""The executor's safety logic without ROS: what is stale, and what is commanded."""

import numpy as np
import pytest

from evorbc_ros.executor import PrimitiveExecutor
from evorbc_ros.laser import InputError
from evorbc_ros.robots.four_ws import FourWSGeometry, robot_type


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
