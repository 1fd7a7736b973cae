"""The arbitrator node's adaptation: parameter, odometry, reset service, diagnostics.

In-process and hermetic (the ``ros`` fixture: no discovery outside the process), as the
other single-node tests (docs/design.md section 24).
"""

import math

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from nav_msgs.msg import Odometry
from rclpy.parameter import Parameter
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Empty

from evorbc_ros.adaptation.motion import extend_arc
from evorbc_ros.nodes.arbitrator import ArbitratorNode
from evorbc_ros.nodes.common import SENSOR_DATA, vector_message

FAST = {"diagnostics_period": 0.1}
RANGES = [0.0] * 8
GOAL = [1.0] + [0.0] * 8  # the goal straight ahead: the same primitive every cycle


def odometry(t, x, y, h):
    msg = Odometry()
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(t * 100_000_000, 1_000_000_000)
    msg.header.frame_id = "odom"
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(h / 2), math.cos(h / 2)
    return msg


def test_adaptation_parameter_odometry_reset_and_diagnostics(ros):
    node = ros.make(ArbitratorNode, adaptation=True, **FAST)
    assert node.controller.adaptation is not None
    genes = ros.listen(Float64MultiArray, "evorbc/primitive")
    reports = ros.listen(DiagnosticArray, "/diagnostics")
    rf, gs = ros.arbitrator_inputs()
    odom = ros.publisher(Odometry, "odom", SENSOR_DATA)
    ros.connected(odom)
    rep = node.controller.repertoire
    # Readings alone do not make a choice while adapting: the pose of the cycle must come.
    rf.publish(vector_message(RANGES))
    gs.publish(vector_message(GOAL))
    ros.spin_until(lambda: False, timeout=0.3)
    assert genes == []
    x = y = h = 0.0
    for t in range(12):  # an intact robot: each cycle moves as the primitive's settled arc
        odom.publish(odometry(t, x, y, h))
        assert ros.spin_until(lambda t=t: len(genes) == t + 1)
        k = node.controller.last_index
        dx, dy, dh = extend_arc(*rep.behaviour[k], rep.heading[k], rep.eval_time, 0.1)
        x, y = x + math.cos(h) * dx - math.sin(h) * dy, y + math.sin(h) * dx + math.cos(h) * dy
        h += dh
        rf.publish(vector_message(RANGES))
        gs.publish(vector_message(GOAL))
    state = node.controller.adaptation_state()
    assert state["observations"] >= 1 and state["uncertainty"] < 1.0

    def reported():
        found = [
            {kv.key: kv.value for kv in s.values}
            for msg in reports
            for s in msg.status
            if s.name == "/arbitrator"
        ]
        return found and "adaptation: observations" in found[-1] and found[-1]

    def observed():  # a report made after the observations (earlier ones may come first)
        last = reported()
        return bool(last) and int(last["adaptation: observations"]) >= 1

    assert ros.spin_until(observed, timeout=5.0)
    assert float(reported()["adaptation: uncertainty"]) < 1.0

    client = ros.helper.create_client(Empty, "/arbitrator/reset_adaptation")
    assert client.wait_for_service(timeout_sec=5.0)
    future = client.call_async(Empty.Request())
    assert ros.spin_until(future.done)
    assert node.controller.adaptation_state()["observations"] == 0

    # Off, live: the readings alone choose again, and what was learned is gone.
    assert node.set_parameters([Parameter("adaptation", value=False)])[0].successful
    assert node.controller.adaptation is None
    n = len(genes)
    ros.spin_until(lambda: len(genes) > n, timeout=2.0)  # the readings already waiting
    n = len(genes)
    rf.publish(vector_message(RANGES))
    gs.publish(vector_message(GOAL))
    assert ros.spin_until(lambda: len(genes) == n + 1)
    assert node.set_parameters([Parameter("adaptation", value=True)])[0].successful
    assert node.controller.adaptation_state()["observations"] == 0


def test_adaptation_expected_settled_reads_the_file_beside_the_repertoire_and_refuses_a_bad_one(
    ros, tmp_path
):
    """``adaptation_expected: settled`` compares observations with the settled outcomes
    shipped beside the repertoire; a bad file fails the configure, or refuses the live
    change, in one line (docs/design/adaptation.md)."""
    from evorbc_ros.adaptation.settled import load_settled, settled_path
    from evorbc_ros.nodes.common import StartupError

    node = ros.make(ArbitratorNode, adaptation=True, adaptation_expected="settled", **FAST)
    rep = node.controller.repertoire
    shipped = load_settled(settled_path(node.controller.repertoire_path), rep)
    assert node.controller.adaptation.model.expected.tobytes() == shipped.tobytes()
    assert node.health(0.0).values["adaptation: expected"] == "settled"
    # Live: the value it has changes nothing; back to recorded starts again from the prior
    # against the recorded outcomes.
    model = node.controller.adaptation.model
    assert node.set_parameters([Parameter("adaptation_expected", value="settled")])[0].successful
    assert node.controller.adaptation.model is model
    assert node.set_parameters([Parameter("adaptation_expected", value="recorded")])[0].successful
    model = node.controller.adaptation.model
    assert model.expected.tobytes() == model.recorded.tobytes() != shipped.tobytes()

    bad = tmp_path / "bad.settled.json"
    bad.write_text(settled_path(node.controller.repertoire_path).read_text()[:200])
    problem = (
        f"parameter adaptation_expected is settled, but {bad}: truncated settled outcomes file"
    )
    with pytest.raises(StartupError, match=f"^{problem}"):
        ros.make(ArbitratorNode, adaptation_expected="settled", settled_outcomes=str(bad))
    other = ros.make(ArbitratorNode, adaptation=True, settled_outcomes=str(bad), **FAST)
    result = other.set_parameters([Parameter("adaptation_expected", value="settled")])[0]
    assert not result.successful and result.reason.startswith(problem)
    assert "\n" not in result.reason
    assert other.get_parameter("adaptation_expected").value == "recorded"
    model = other.controller.adaptation.model  # still adapting against the recorded ones
    assert model.expected.tobytes() == model.recorded.tobytes()
