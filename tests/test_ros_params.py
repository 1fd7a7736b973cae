"""Node parameters as ROS users expect them: the shipped parameter files apply under any
namespace, ``ros2 param set`` never claims a success that changes nothing, and the one
live parameter changes what the node does."""

import numpy as np
import pytest
import rclpy
import yaml
from rclpy.node import Node
from rclpy.parameter import Parameter
from ros_helpers import ros_with_args
from std_msgs.msg import Float64MultiArray

from evorbc_ros.config import config_dir
from evorbc_ros.nodes.arbitrator import ArbitratorNode
from evorbc_ros.nodes.common import vector_message
from evorbc_ros.nodes.laser_sensor import LaserSensorNode
from evorbc_ros.nodes.primitive_executor import PrimitiveExecutorNode
from evorbc_ros.nodes.radar_sensor import RadarSensorNode

NODES_FILE = config_dir() / "ros" / "evorbc_nodes.yaml"
BRIDGE_FILE = config_dir() / "ros" / "sim_bridge.yaml"
#: rclpy's own parameters: use_sim_time is applied live by rclpy itself.
RCLPY_PARAMETERS = {"use_sim_time", "start_type_description_service"}


def file_section(path, node):
    """The parameters a file gives ``node`` (under the any-namespace key ``/**``)."""
    return yaml.safe_load(path.read_text())["/**"][node]["ros__parameters"]


@pytest.mark.parametrize("namespace", ["", "robot1", "fleet/robot2"])
@pytest.mark.parametrize(
    ("name", "cls", "robot"),
    [
        ("laser_sensor", LaserSensorNode, None),
        ("radar_sensor", RadarSensorNode, None),
        ("arbitrator", ArbitratorNode, None),
        ("primitive_executor", PrimitiveExecutorNode, None),
        ("primitive_executor", PrimitiveExecutorNode, "hexapod"),
    ],
)
def test_the_shipped_parameter_file_applies_under_any_namespace(
    monkeypatch, name, cls, robot, namespace
):
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    params = file_section(NODES_FILE, name)
    with ros_with_args("--params-file", str(NODES_FILE)) as ros:
        extra = {"robot": robot} if robot else {}
        node = ros.make(cls, namespace=namespace, **extra)
        # rcl matched the file's section to this node, wherever it runs ...
        assert set(params) <= set(node._parameter_overrides)
        # ... and the node declares every key it sets, with the file's value.
        assert not {k for k in params if not node.has_parameter(k)}
        for key, value in {**params, **extra}.items():
            assert node.get_parameter(key).value == value


def test_a_changed_value_in_the_file_reaches_a_namespaced_node(monkeypatch, tmp_path):
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    data = yaml.safe_load(NODES_FILE.read_text())
    data["/**"]["primitive_executor"]["ros__parameters"]["wheel_radius"] = 0.05
    data["/**"]["laser_sensor"]["ros__parameters"]["laser_x"] = 0.125
    edited = tmp_path / "my_robot.yaml"
    edited.write_text(yaml.safe_dump(data))
    with ros_with_args("--params-file", str(edited)) as ros:
        executor = ros.make(PrimitiveExecutorNode, namespace="robot1")
        laser = ros.make(LaserSensorNode, namespace="robot1")
        assert executor.wheel_radius == 0.05
        assert laser.get_parameter("laser_x").value == 0.125


@pytest.mark.parametrize("namespace", ["", "robot1"])
def test_the_bridge_parameter_file_applies_under_any_namespace(monkeypatch, namespace):
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    params = file_section(BRIDGE_FILE, "sim_bridge")
    context = rclpy.Context()
    rclpy.init(context=context, args=["--ros-args", "--params-file", str(BRIDGE_FILE)])
    try:
        node = Node("sim_bridge", namespace=namespace, context=context)
        overrides = {k: p.value for k, p in node._parameter_overrides.items()}
        assert {k: overrides.get(k) for k in params} == params
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def changed(value):
    """Another value of the same type (what a user might try with ros2 param set)."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, (int, float)):
        return value * 2 + 1
    if isinstance(value, str):
        return value + "_other"
    return [*value, "other"]


def assert_read_only_except(node, live):
    names = set(node.list_parameters([], 1).names) - RCLPY_PARAMETERS
    assert live <= names
    for name in sorted(names - live):
        before = node.get_parameter(name).value
        result = node.set_parameters([Parameter(name, value=changed(before))])[0]
        assert not result.successful, f"{name} claims it was set"
        assert "read-only" in result.reason
        assert node.get_parameter(name).value == before


@pytest.mark.parametrize(
    ("cls", "params", "live"),
    [
        (LaserSensorNode, {}, set()),
        (RadarSensorNode, {}, set()),
        (ArbitratorNode, {"robot": "4ws-5"}, set()),
        (PrimitiveExecutorNode, {}, {"wheel_radius"}),
        (PrimitiveExecutorNode, {"robot": "hexapod"}, {"wheel_radius"}),
    ],
)
def test_parameters_read_at_start_up_are_read_only(ros, cls, params, live):
    assert_read_only_except(ros.make(cls, **params), live)


def test_the_bridge_parameters_are_read_only(ros):
    from sim_bridge.bridge_node import SimBridgeNode

    node = ros.make(SimBridgeNode)
    try:
        assert_read_only_except(node, set())
    finally:
        node.world.close()


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
    for bad in (-1.0, 0.0, float("nan"), "big"):
        result = node.set_parameters([Parameter("wheel_radius", value=bad)])[0]
        assert not result.successful
        assert result.reason.startswith("parameter wheel_radius must be a positive number")
    assert node.get_parameter("wheel_radius").value == 0.04
    result = node.set_parameters([Parameter("wheel_radius", value=1)])[0]  # an int is a number
    assert result.successful and node.wheel_radius == 1.0
