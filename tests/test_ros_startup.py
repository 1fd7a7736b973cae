"""Start-up checks and logs, in-process: a controller for another robot is refused in one
line that reaches /rosout, the executor stays silent until the arbitrator speaks, primitives
for another robot are refused, and goals come from latched and volatile publishers alike."""

import os

import pytest
from geometry_msgs.msg import PointStamped, PoseStamped
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import Log
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ros_helpers import ros_with_args
from std_msgs.msg import Float64MultiArray

from evorbc_ros.config import config_dir
from evorbc_ros.defaults import default_arbitrator
from evorbc_ros.nodes.arbitrator import ArbitratorNode
from evorbc_ros.nodes.common import LATCHED, RELIABLE, StartupError, vector_message
from evorbc_ros.nodes.primitive_executor import PrimitiveExecutorNode
from evorbc_ros.nodes.radar_sensor import RadarSensorNode

SHIPPED_4WS = default_arbitrator("4ws-5")
#: /rosout as rcl publishes it (reliable, transient local): a late subscriber still gets
#: what a node logged just before it failed.
ROSOUT = QoSProfile(
    depth=1000,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)


def test_a_controller_for_another_robot_is_refused_naming_both(ros):
    with pytest.raises(StartupError) as info:
        ros.make(ArbitratorNode, arbitrator=str(SHIPPED_4WS), robot="4ws-3")
    assert str(info.value) == (
        f"{SHIPPED_4WS}: is a controller for robot 4ws-5, but parameter robot is 4ws-3"
    )


def test_no_shipped_controller_for_the_robot_says_how_to_make_one(ros):
    with pytest.raises(StartupError) as info:
        ros.make(ArbitratorNode, robot="2ws-3")
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("parameter robot: no controller ships for robot 2ws-3")
    assert "evorbc-evolve repertoire --robot 2ws-3" in message
    assert message.endswith("set arbitrator:=a.json and repertoire:=r.json")
    with pytest.raises(StartupError, match="parameter robot must be one of"):
        ros.make(ArbitratorNode, robot="tank")


def test_the_robot_parameter_picks_the_robots_shipped_controller(ros):
    node = ros.make(ArbitratorNode, robot="hexapod")
    assert node.controller.spec.robot == "hexapod"
    assert node.controller.arbitrator_path == str(default_arbitrator("hexapod"))
    node = ros.make(ArbitratorNode)  # unset: the 4ws-5 one, as before
    assert node.controller.arbitrator_path == str(SHIPPED_4WS)


def test_start_up_errors_reach_rosout(ros):
    logs = ros.listen(Log, "/rosout", ROSOUT)
    with pytest.raises(StartupError) as info:
        ros.make(ArbitratorNode, arbitrator=str(SHIPPED_4WS), robot="hexapod")
    expected = f"cannot start: {info.value}"

    def logged():
        return [m for m in logs if m.name == "arbitrator" and m.msg == expected]

    assert ros.spin_until(lambda: logged(), timeout=10)
    assert logged()[0].level == Log.FATAL


def executor_commands(ros, **params):
    node = ros.make(PrimitiveExecutorNode, **params)
    wheels = ros.listen(Float64MultiArray, "wheel_velocity_controller/commands")
    steering = ros.listen(Float64MultiArray, "steering_position_controller/commands")
    return node, wheels, steering


def test_the_executor_publishes_nothing_before_the_first_primitive(ros):
    node, wheels, steering = executor_commands(ros)
    prim, rf, gs = ros.executor_inputs()
    # Sensors arrive, no primitive: another node (teleop) may be driving; the stale stop
    # must not fight it. Five periods pass.
    for _ in range(5):
        rf.publish(vector_message([0.0] * 6))
        gs.publish(vector_message([1, 0, 0, 0]))
        ros.spin_until(lambda: False, timeout=0.1)
    assert wheels == [] and steering == []
    prim.publish(vector_message([1.0, 0, 0, 0, 0]))
    assert ros.spin_until(lambda: len(wheels) == 1)
    assert wheels[0].data[0] == pytest.approx(10.0)
    # From then on the stale stop is as before: silence stops the robot.
    assert ros.spin_until(lambda: wheels[-1].data[0] == 0.0, timeout=5)
    assert node.stopped_reason.startswith("stale input")


def test_zero_commands_before_the_first_primitive_on_request(ros):
    _, wheels, steering = executor_commands(ros, zero_before_first_primitive=True)
    ros.executor_inputs()
    assert ros.spin_until(lambda: len(wheels) >= 2 and len(steering) >= 2)
    assert all(list(w.data) == [0.0] * 4 for w in wheels)


@pytest.mark.parametrize(
    ("robot", "genes", "names", "needle"),
    [
        # As many genes, another robot: 2ws-3 steers each front wheel, 4ws-3 each axle.
        (
            "4ws-3",
            [1.0, 0.5, 0.5],
            ["speed", "angle_fl", "angle_fr"],
            "refused a 2ws-3 primitive (speed, angle_fl, angle_fr): this executor drives a "
            "4ws-3 (speed, angle_front, angle_rear); is the arbitrator for another robot?",
        ),
        (
            "4ws-3",
            [1.0, 0.5, 0.5, 0.5, 0.5],
            ["speed", "angle_fl", "angle_fr", "angle_rl", "angle_rr"],
            "refused a 4ws-5 primitive",
        ),
    ],
)
def test_a_primitive_for_another_robot_is_refused(ros, robot, genes, names, needle):
    node, wheels, _ = executor_commands(ros, robot=robot)
    errors = []
    node.get_logger().error = lambda msg, **kw: errors.append(msg)
    prim, rf, gs = ros.executor_inputs()
    rf.publish(vector_message([0.0] * 6))
    gs.publish(vector_message([1, 0, 0, 0]))
    prim.publish(vector_message(genes, names))
    assert ros.spin_until(lambda: errors)
    assert errors[0].startswith(f"evorbc/primitive: {needle}")
    ros.spin_until(lambda: False, timeout=0.3)
    assert wheels == []  # never driven with it, and nothing sent at all
    # Its own robot's primitive runs.
    rf.publish(vector_message([0.0] * 6))
    gs.publish(vector_message([1, 0, 0, 0]))
    ros.spin_until(lambda: node.logic.last_seen["evorbc/goal_sectors"] is not None)
    prim.publish(vector_message([1.0, 0.5, 0.5], ["speed", "angle_front", "angle_rear"]))
    assert ros.spin_until(lambda: wheels and wheels[-1].data[0] != 0.0)


def goal_message(cls, x, y):
    msg = cls()
    msg.header.frame_id = "odom"
    point = msg.point if cls is PointStamped else msg.pose.position
    point.x, point.y = x, y
    return msg


def test_goals_from_a_volatile_publisher_are_taken(ros):
    logs = ros.listen(Log, "/rosout", ROSOUT)
    node = ros.make(RadarSensorNode)
    pub = ros.publisher(PointStamped, "goal", RELIABLE)  # ros2 topic pub's default QoS
    ros.connected(pub)
    pub.publish(goal_message(PointStamped, 1.0, 2.0))
    assert ros.spin_until(lambda: node.goal == (1.0, 2.0, "odom"))
    ros.spin_until(lambda: False, timeout=0.2)
    # Taken without a false alarm from the latched subscription.
    assert not [m.msg for m in logs if m.name == "radar_sensor" and m.level >= Log.WARN]


def test_a_latched_goal_published_before_the_node_started_is_taken(ros):
    pub = ros.publisher(PointStamped, "goal", LATCHED)
    pub.publish(goal_message(PointStamped, 3.0, -1.0))
    node = ros.make(RadarSensorNode)
    assert ros.spin_until(lambda: node.goal == (3.0, -1.0, "odom"))
    pub.publish(goal_message(PointStamped, 4.0, 0.5))  # a new goal replaces it
    assert ros.spin_until(lambda: node.goal == (4.0, 0.5, "odom"))


def test_rviz_goal_poses_are_taken_through_a_remapping(monkeypatch):
    """RViz's goal tool: PoseStamped on /goal_pose, reliable and volatile."""
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    with ros_with_args("-r", "radar_sensor:goal:=/goal_pose") as ros:
        # The paper's four goal sectors, whichever controller ships (its layout is the
        # node's default).
        layout = str(config_dir() / "sensors" / "4ws.yaml")
        node = ros.make(RadarSensorNode, goal_type="pose", sensor_layout=layout)
        out = ros.listen(Float64MultiArray, "evorbc/goal_sectors")
        pub = ros.publisher(PoseStamped, "/goal_pose", RELIABLE)
        ros.connected(pub)
        pub.publish(goal_message(PoseStamped, 0.0, 2.0))
        assert ros.spin_until(lambda: node.goal == (0.0, 2.0, "odom"))
        odom_pub = ros.publisher(Odometry, "odom")
        ros.connected(odom_pub)
        odom = Odometry()
        odom.header.frame_id = "odom"
        odom.pose.pose.orientation.w = 1.0
        odom_pub.publish(odom)
        assert ros.spin_until(lambda: out)
        assert list(out[0].data) == [0, 1, 0, 0]  # the goal is left: the 90 deg sector


def test_a_record_file_that_is_not_a_regular_file_is_refused_without_blocking(ros, tmp_path):
    fifo = tmp_path / "choices.fifo"
    os.mkfifo(fifo)  # opening it for writing would block until a reader came
    with pytest.raises(StartupError) as info:
        ros.make(ArbitratorNode, record_file=str(fifo))
    assert str(info.value) == f"parameter record_file: {fifo} is not a regular file"
