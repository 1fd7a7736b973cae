"""Node parameters as ROS users expect them (docs/design.md section 9, "Parameters").

* each node's shipped parameter file (``config/ros/<node>.yaml``, key ``/**``) applies under
  any namespace, and holds only parameters of its table, with valid values;
* every numeric parameter has its range in its descriptor (``ros2 param describe``);
* a parameter read once refuses another value with the reason, but takes the value it has,
  so ``ros2 param load`` of the shipped file works on a running node; a lifecycle node takes
  any valid value while unconfigured; the live ``wheel_radius`` changes what the node does;
* the topic-name parameters of earlier versions are refused, naming the remapping.
"""

import numpy as np
import pytest
import yaml
from rclpy.lifecycle import TransitionCallbackReturn
from rclpy.parameter import Parameter
from rclpy.qos import ReliabilityPolicy
from ros_helpers import ros_with_args
from std_msgs.msg import Float64MultiArray

from evorbc_ros.config import config_dir
from evorbc_ros.node_parameters import PARAMETERS, REMOVED
from evorbc_ros.nodes.arbitrator import ArbitratorNode
from evorbc_ros.nodes.common import StartupError, vector_message
from evorbc_ros.nodes.laser_sensor import LaserSensorNode
from evorbc_ros.nodes.primitive_executor import PrimitiveExecutorNode
from evorbc_ros.nodes.radar_sensor import RadarSensorNode
from sim_bridge import bridge_parameters, recorder
from sim_bridge.graph import sim_graph

NODES = {
    "laser_sensor": LaserSensorNode,
    "radar_sensor": RadarSensorNode,
    "arbitrator": ArbitratorNode,
    "primitive_executor": PrimitiveExecutorNode,
}
TABLES = {
    **PARAMETERS,
    "sim_bridge": bridge_parameters.PARAMETERS,
    "recorder": recorder.PARAMETERS,
}
#: rclpy's own parameters.
RCLPY_PARAMETERS = {"use_sim_time", "start_type_description_service"}


def param_file(node):
    return config_dir() / "ros" / f"{node}.yaml"


def file_values(node):
    """The parameters a node's file gives (under the any-node key ``/**``)."""
    return yaml.safe_load(param_file(node).read_text())["/**"]["ros__parameters"]


@pytest.mark.parametrize("node", sorted(TABLES))
def test_each_shipped_file_holds_valid_values_of_its_nodes_table(node):
    specs = {s.name: s for s in TABLES[node]}
    values = file_values(node)
    assert set(values) <= set(specs), set(values) - set(specs)
    for name, value in values.items():
        assert specs[name].problem(value) == "", name
    # The file shows every parameter a user may want to change (all but the bridge's
    # readiness lists, which evorbc-sim and the launch file fill in).
    assert set(specs) - set(values) <= {
        "wait_for_subscribers",
        "wait_for_publishers",
        "wait_for_ready",
    }


@pytest.mark.parametrize("namespace", ["", "robot1", "fleet/robot2"])
@pytest.mark.parametrize("name", sorted(NODES))
def test_the_shipped_file_applies_under_any_namespace(monkeypatch, name, namespace):
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    values = file_values(name)
    with ros_with_args("--params-file", str(param_file(name))) as ros:
        node = ros.make(NODES[name], namespace=namespace)
        for key, value in values.items():
            got = node.get_parameter(key).value
            assert (list(got) if isinstance(got, (list, tuple)) else got) == value, key


def test_a_changed_value_in_the_file_reaches_a_namespaced_node(monkeypatch, tmp_path):
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    data = yaml.safe_load(param_file("primitive_executor").read_text())
    data["/**"]["ros__parameters"]["wheel_radius"] = 0.05
    edited = tmp_path / "my_robot.yaml"
    edited.write_text(yaml.safe_dump(data))
    with ros_with_args("--params-file", str(edited)) as ros:
        executor = ros.make(PrimitiveExecutorNode, namespace="robot1")
        assert executor.wheel_radius == 0.05


def describe(node):
    names = sorted(set(node.list_parameters([], 1).names) - RCLPY_PARAMETERS)
    return dict(zip(names, node.describe_parameters(names), strict=True))


def assert_described(node, table):
    described = describe(node)
    assert set(described) == {s.name for s in table}
    for spec in table:
        d = described[spec.name]
        assert d.description == spec.description
        if spec.kind is float:
            (r,) = d.floating_point_range
            assert (r.from_value, r.to_value) == (spec.minimum, spec.maximum), spec.name
        elif spec.kind is int:
            (r,) = d.integer_range
            assert (r.from_value, r.to_value) == (spec.minimum, spec.maximum), spec.name
        when = "applied live" if spec.live else "read at"
        assert d.additional_constraints.startswith(when), spec.name


@pytest.mark.parametrize("name", sorted(NODES))
def test_every_parameter_is_described_with_its_range(ros, name):
    assert_described(ros.make(NODES[name]), PARAMETERS[name])


def test_the_bridge_describes_every_parameter_with_its_range(ros):
    from sim_bridge.bridge_node import SimBridgeNode

    node = ros.make(SimBridgeNode)
    try:
        assert_described(node, bridge_parameters.PARAMETERS)
    finally:
        node.world.close()


def test_every_numeric_parameter_has_a_range():
    for table in TABLES.values():
        for spec in table:
            if spec.kind in (int, float):
                assert spec.minimum is not None and spec.maximum is not None, spec.name


def changed(value, choices=()):
    """Another valid value (what a user might try with ros2 param set)."""
    if choices and isinstance(value, str):
        return next(c for c in choices if c != value)
    if isinstance(value, bool):
        return not value
    if isinstance(value, float):
        return value / 2 + 0.001
    if isinstance(value, int):
        return value + 1
    if isinstance(value, str):
        return value + "_other"
    return list(value[:1]) if value else ["other"]


def assert_read_once(node, table, when):
    """Another value is refused with the reason; the value it has is taken."""
    for spec in table:
        before = node.get_parameter(spec.name).value
        other = changed(before, spec.choices)
        result = node.set_parameters([Parameter(spec.name, value=other)])[0]
        if spec.live:
            continue
        assert not result.successful, f"{spec.name} claims it was set"
        assert result.reason.startswith(f"parameter {spec.name} is read at "), result.reason
        if not spec.at_start:
            assert f"is read {when}" in result.reason
        assert node.get_parameter(spec.name).value == before
    # What ros2 param load of the node's own values does: every one succeeds.
    current = [node.get_parameter(s.name) for s in table if not s.live]
    assert all(r.successful for r in node.set_parameters(current))


@pytest.mark.parametrize(
    ("name", "params"),
    [
        ("laser_sensor", {}),
        ("radar_sensor", {}),
        ("arbitrator", {"robot": "4ws-5"}),
        ("primitive_executor", {}),
        ("primitive_executor", {"robot": "hexapod"}),
    ],
)
def test_parameters_read_once_refuse_a_change_and_take_their_own_value(ros, name, params):
    when = "at configure" if name in ("arbitrator", "primitive_executor") else "at start-up"
    assert_read_once(ros.make(NODES[name], **params), PARAMETERS[name], when)


def test_the_bridge_parameters_refuse_a_change(ros):
    from sim_bridge.bridge_node import SimBridgeNode

    node = ros.make(SimBridgeNode)
    try:
        assert_read_once(node, bridge_parameters.PARAMETERS, "at start-up")
    finally:
        node.world.close()


def test_a_lifecycle_node_takes_any_valid_value_while_unconfigured(ros, tmp_path):
    node = ros.make(ArbitratorNode, autostart=False)
    assert node.state == "unconfigured"
    ok = node.set_parameters([Parameter("robot", value="hexapod")])[0]
    assert ok.successful
    bad = node.set_parameters([Parameter("diagnostics_period", value=1000.0)])[0]
    assert not bad.successful and "out of range" in bad.reason  # rclpy checks the range
    assert node.trigger_configure() == TransitionCallbackReturn.SUCCESS
    assert node.controller.spec.robot == "hexapod"  # read at configure
    refused = node.set_parameters([Parameter("robot", value="4ws-5")])[0]
    assert not refused.successful
    assert refused.reason == (
        "parameter robot is read at configure: deactivate, clean up, set it and configure again"
    )


def test_a_whole_number_for_a_float_parameter_is_its_value(ros):
    node = ros.make(PrimitiveExecutorNode)  # trajectory_rate is 0.0
    assert node.set_parameters([Parameter("trajectory_rate", value=0)])[0].successful
    assert not node.set_parameters([Parameter("trajectory_rate", value=1)])[0].successful
    assert node.parameters()["trajectory_rate"] == 0.0


@pytest.mark.parametrize(
    ("name", "removed"), [(n, old) for n, table in REMOVED.items() for old in table]
)
def test_a_removed_topic_parameter_is_refused_naming_the_remap(monkeypatch, name, removed):
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    with ros_with_args("-p", f"{removed}:=/my/topic") as ros, pytest.raises(StartupError) as info:
        ros.make(NODES[name])
    topic = REMOVED[name][removed].split(" ")[0]
    assert str(info.value).startswith(
        f"parameter {removed} was removed: topics have fixed names now; remap instead: "
        f"--ros-args -r {topic}:=<your topic>"
    )


@pytest.mark.parametrize("removed", sorted(bridge_parameters.REMOVED))
def test_the_bridge_refuses_a_removed_topic_parameter(monkeypatch, removed):
    from sim_bridge.bridge_node import SimBridgeNode

    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    with ros_with_args("-p", f"{removed}:=x") as ros, pytest.raises(StartupError) as info:
        ros.make(SimBridgeNode)
    assert f"-r {bridge_parameters.REMOVED[removed]}:=<your topic>" in str(info.value)


def test_the_topics_are_remapped_instead(monkeypatch):
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    with ros_with_args("-r", "scan:=/front/scan", "-r", "evorbc/rangefinders:=rf") as ros:
        node = ros.make(LaserSensorNode)
        assert node.sub.topic_name == "/front/scan"
        assert node.pub.topic_name == "/rf"


def test_wheel_radius_is_applied_live_and_validated(ros):
    node = ros.make(PrimitiveExecutorNode)
    wheels = ros.listen(Float64MultiArray, "wheel_velocity_controller/commands")
    prim, rf, gs = ros.executor_inputs()

    def run_primitive():
        count = len(wheels)
        rf.publish(vector_message([0.0] * 6))
        gs.publish(vector_message([1, 0, 0, 0]))
        ros.spin_until(lambda: node.logic.last_seen["evorbc/goal_sectors"] is not None)
        prim.publish(vector_message([1.0, 0, 0, 0, 0]))  # full speed, 0.2 m/s
        assert ros.spin_until(lambda: len(wheels) > count and wheels[-1].data[0] != 0.0)
        return wheels[-1].data

    np.testing.assert_allclose(run_primitive(), [0.2 / 0.02] * 4)
    result = node.set_parameters([Parameter("wheel_radius", value=0.04)])[0]
    assert result.successful
    np.testing.assert_allclose(run_primitive(), [0.2 / 0.04] * 4)
    for bad in (-1.0, float("nan"), "big", 11.0):
        result = node.set_parameters([Parameter("wheel_radius", value=bad)])[0]
        assert not result.successful
        assert "wheel_radius" in result.reason
    assert node.get_parameter("wheel_radius").value == 0.04
    result = node.set_parameters([Parameter("wheel_radius", value=1)])[0]  # an int is a number
    assert result.successful and node.wheel_radius == 1.0
    # 0 means the robot's own again.
    assert node.set_parameters([Parameter("wheel_radius", value=0.0)])[0].successful
    assert node.wheel_radius == 0.02


def subscription_reliability(node, topic):
    (info,) = node.get_subscriptions_info_by_topic(topic)
    return info.qos_profile.reliability


@pytest.mark.parametrize("cls, topic", [(LaserSensorNode, "/scan"), (RadarSensorNode, "/odom")])
def test_sensor_streams_are_best_effort_unless_input_qos_is_reliable(ros, cls, topic):
    # Best effort takes any driver's stream; a lockstep graph asks for reliable, so a
    # first message that arrives before the reader's side of the match is not dropped.
    assert subscription_reliability(ros.make(cls), topic) == ReliabilityPolicy.BEST_EFFORT


@pytest.mark.parametrize("cls, topic", [(LaserSensorNode, "/scan"), (RadarSensorNode, "/odom")])
def test_input_qos_reliable_subscribes_reliably(ros, cls, topic):
    node = ros.make(cls, input_qos="reliable")
    assert subscription_reliability(node, topic) == ReliabilityPolicy.RELIABLE


def test_the_lockstep_graph_asks_its_nodes_for_reliable_inputs():
    lockstep, realtime = sim_graph(maze="gaps"), sim_graph(maze="gaps", mode="realtime")
    for name in ("laser_sensor", "radar_sensor", "arbitrator"):
        assert lockstep.node(name).parameters["input_qos"] == "reliable"
        assert "input_qos" not in realtime.node(name).parameters  # the node's default
