"""Every node reports its health on /diagnostics (docs/design.md section 9, "Diagnostics").

Levels follow the inputs: OK while they flow, WARN when one is old or missing, messages
were skipped or the robot is stopped, ERROR when primitives for another robot are refused
or a configure failed. Ages are on the node's clock, so the tests move simulated time.
"""

import math

import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PointStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64MultiArray

from evorbc_ros.health import ERROR, OK, WARN, Health, Meter, report_input, report_skipped
from evorbc_ros.nodes.arbitrator import ArbitratorNode
from evorbc_ros.nodes.common import LATCHED, vector_message
from evorbc_ros.nodes.laser_sensor import LaserSensorNode
from evorbc_ros.nodes.primitive_executor import PrimitiveExecutorNode
from evorbc_ros.nodes.radar_sensor import RadarSensorNode

FAST = {"diagnostics_period": 0.1, "use_sim_time": True}


def test_a_meter_gives_rates_per_second_of_the_nodes_clock_and_ages():
    m = Meter()
    assert m.age(1.0) is None and m.rate(1.0) is None  # the first call sets the mark
    for k in range(10):
        m.tick(1.0 + 0.1 * k)
    assert m.new_since_report() == 10
    assert m.rate(2.0) == pytest.approx(10.0)
    assert m.age(2.5) == pytest.approx(0.6)
    assert m.rate(2.0) is None  # the clock stood still (a paused simulation)


def test_reports_warn_about_missing_old_and_skipped_input():
    h = Health()
    report_input(h, "scan", Meter(), 5.0, 1.0)
    assert (h.level, h.message) == (WARN, "no scan yet")
    m = Meter()
    m.tick(1.0)
    h = Health()
    report_input(h, "scan", m, 1.5, 1.0)
    assert h.level == OK and h.values["scan age (s)"] == "0.500"
    report_input(h, "scan", m, 3.0, 1.0)
    assert (h.level, h.message) == (WARN, "scan is 2.00 s old")
    h, skipped = Health(), Meter()
    skipped.tick(1.0)
    report_skipped(h, "scan", skipped, 1.0)
    assert (h.level, h.message) == (WARN, "1 scan message(s) skipped")
    h = Health()
    report_skipped(h, "scan", skipped, 2.0)
    assert h.level == OK and h.values["scan skipped"] == "1"
    h.worse(ERROR, "bad")
    h.worse(WARN, "less bad")
    assert (h.level, h.message) == (ERROR, "bad")


def statuses(ros, name):
    got = ros.listen(DiagnosticArray, "/diagnostics")
    return lambda: [s for msg in got for s in msg.status if s.name == f"/{name}"]


def latest_is(ros, seen, level, message=None):
    """Wait until the latest status has ``level`` (and ``message``); return it.

    A status computed before the change it should show may still be on its way, so the
    tests wait for the state rather than take the next message.
    """

    def ok():
        s = seen()
        return bool(s) and s[-1].level == level and message in (None, s[-1].message)

    assert ros.spin_until(ok, timeout=5.0), seen()[-1:] if seen() else "no status"
    return seen()[-1]


def values(status):
    return {kv.key: kv.value for kv in status.values}


def scan(n=360):
    msg = LaserScan()
    msg.angle_min, msg.angle_increment = -math.pi, 2 * math.pi / max(n, 1)
    msg.angle_max = msg.angle_min + msg.angle_increment * (n - 1)
    msg.range_max = 10.0
    msg.ranges = [5.0] * n
    return msg


def test_the_laser_node_reports_its_scans(ros):
    ros.make(LaserSensorNode, **FAST)
    ros.set_clock(1.0)
    seen = statuses(ros, "laser_sensor")
    pub = ros.publisher(LaserScan, "scan")
    ros.connected(pub)
    latest_is(ros, seen, DiagnosticStatus.WARN, "no scan yet")
    pub.publish(scan())
    status = latest_is(ros, seen, DiagnosticStatus.OK, "ok")
    assert values(status)["scan age (s)"] == "0.000"
    ros.set_clock(3.0)  # two seconds without a scan
    latest_is(ros, seen, DiagnosticStatus.WARN, "scan is 2.00 s old")
    pub.publish(scan(0))  # a 0-beam scan: skipped, and said
    assert ros.spin_until(lambda: seen()[-1].message == "1 scan message(s) skipped")


def test_the_radar_node_warns_until_it_has_a_goal(ros):
    ros.make(RadarSensorNode, **FAST)
    ros.set_clock(1.0)
    seen = statuses(ros, "radar_sensor")
    odom = ros.publisher(Odometry, "odom")
    goal = ros.publisher(PointStamped, "goal", LATCHED)
    ros.connected(odom)
    msg = Odometry()
    msg.pose.pose.orientation.w = 1.0
    odom.publish(msg)
    assert ros.spin_until(lambda: seen() and seen()[-1].message == "no goal yet")
    target = PointStamped()
    target.point.x = 1.0
    goal.publish(target)
    odom.publish(msg)
    assert ros.spin_until(lambda: seen()[-1].level == DiagnosticStatus.OK)
    assert values(seen()[-1])["goal"] == "(1.000, 0.000) in ''"


def test_the_executor_reports_a_stale_stop_and_refused_primitives(ros):
    node = ros.make(PrimitiveExecutorNode, **FAST)
    ros.set_clock(1.0)
    seen = statuses(ros, "primitive_executor")
    prim, rf, gs = ros.executor_inputs()
    rf.publish(vector_message([0.0] * 6))
    gs.publish(vector_message([1, 0, 0, 0]))
    prim.publish(vector_message([1.0, 0, 0, 0, 0]))
    assert ros.spin_until(lambda: node.primitive_seen)
    status = latest_is(ros, seen, DiagnosticStatus.OK)
    assert values(status)["robot"] == "running"
    assert values(status)["state"] == "active" and status.hardware_id == "4ws-5"
    ros.set_clock(2.0)  # every input is now 1 s old: the stale stop
    assert ros.spin_until(lambda: values(seen()[-1])["robot"].startswith("stopped"))
    assert seen()[-1].level == DiagnosticStatus.WARN
    hexapod = vector_message([0.0] * 4, ["a", "b", "c", "d"])  # another robot's labels
    prim.publish(hexapod)
    assert ros.spin_until(lambda: seen()[-1].level == DiagnosticStatus.ERROR)
    assert seen()[-1].message == "1 primitive(s) for another robot refused"


def test_the_arbitrator_reports_its_state_and_choices(ros, tmp_path):
    ros.make(ArbitratorNode, autostart=False, arbitrator=str(tmp_path / "no.json"), **FAST)
    ros.set_clock(1.0)
    seen = statuses(ros, "arbitrator")
    latest_is(ros, seen, DiagnosticStatus.WARN, "unconfigured: not commanding")
    node = ros.nodes[-1]
    node.trigger_configure()
    failed = f"cannot configure: {tmp_path / 'no.json'}: no such arbitrator file"
    latest_is(ros, seen, DiagnosticStatus.ERROR, failed)
    genes = ros.listen(Float64MultiArray, "evorbc/primitive")
    from rclpy.parameter import Parameter

    node.set_parameters([Parameter("arbitrator", value="")])
    node.trigger_configure()
    node.trigger_activate()
    rf, gs = ros.arbitrator_inputs()
    rf.publish(vector_message([0.0] * 8))
    gs.publish(vector_message([1.0] + [0.0] * 8))
    assert ros.spin_until(lambda: len(genes) == 1)
    status = latest_is(ros, seen, DiagnosticStatus.OK)
    assert values(status)["state"] == "active"
    assert values(status)["last choice"].startswith("[")
