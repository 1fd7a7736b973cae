"""The evorbc nodes in-process: wiring, malformed messages, stale inputs, start-up errors."""

import math

import numpy as np
import pytest
from geometry_msgs.msg import PointStamped
from nav_msgs.msg import Odometry
from neat_helpers import neat_config, network_spec, random_genomes
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64MultiArray

from evorbc_ros.arbitrator import Arbitrator, ArbitratorFile
from evorbc_ros.config import config_dir
from evorbc_ros.nodes.arbitrator import ArbitratorNode
from evorbc_ros.nodes.common import LATCHED, StartupError, vector_message
from evorbc_ros.nodes.laser_sensor import LaserSensorNode
from evorbc_ros.nodes.primitive_executor import PrimitiveExecutorNode
from evorbc_ros.nodes.radar_sensor import RadarSensorNode
from evorbc_ros.sensors import SensorLayout

LAYOUT_FILE = config_dir() / "sensors" / "4ws.yaml"  # the paper's: 6 rangefinders, 4 sectors
LAYOUT = SensorLayout.load(LAYOUT_FILE)


def scan(ranges, angle_min=-math.pi, increment=None):
    msg = LaserScan()
    msg.angle_min = angle_min
    msg.angle_increment = increment if increment is not None else 2 * math.pi / len(ranges)
    msg.angle_max = angle_min + msg.angle_increment * (len(ranges) - 1)
    msg.range_max = 10.0
    msg.ranges = [float(r) for r in ranges]
    return msg


def test_laser_node_publishes_readings_and_skips_malformed_scans(ros):
    node = ros.make(LaserSensorNode, laser_yaw=0.0, sensor_layout=str(LAYOUT_FILE))
    out = ros.listen(Float64MultiArray, "evorbc/rangefinders")
    pub = ros.publisher(LaserScan, "scan")
    ros.connected(pub)
    bad = scan([0.5] * 360)
    bad.angle_increment = 0.0
    pub.publish(bad)
    pub.publish(scan([math.nan] * 360))  # a failed scanner: blind, not "nothing seen"
    pub.publish(scan([0.5] * 360))
    assert ros.spin_until(lambda: len(out) >= 1)
    assert len(out) == 1  # the malformed and the blind scan were skipped, the node kept going
    np.testing.assert_allclose(out[0].data, [0.55] * 6, atol=1e-6)
    assert out[0].layout.dim[0].label.split(",") == LAYOUT.input_names()[:6]
    assert node.context.ok()


def test_radar_node_publishes_goal_sectors(ros):
    node = ros.make(RadarSensorNode, sensor_layout=str(LAYOUT_FILE))
    out = ros.listen(Float64MultiArray, "evorbc/goal_sectors")
    goal_pub = ros.publisher(PointStamped, "goal", LATCHED)
    odom_pub = ros.publisher(Odometry, "odom")
    goal = PointStamped()
    goal.header.frame_id = "odom"
    goal.point.x, goal.point.y = 0.0, 2.0  # straight left of a robot at the origin facing +x
    goal_pub.publish(goal)
    ros.connected(odom_pub)
    assert ros.spin_until(lambda: node.goal is not None)

    def odom(yaw, x=0.0, frame="odom"):
        msg = Odometry()
        msg.header.frame_id = frame
        msg.pose.pose.position.x = x
        msg.pose.pose.orientation.z = math.sin(yaw / 2)
        msg.pose.pose.orientation.w = math.cos(yaw / 2)
        return msg

    odom_pub.publish(odom(0.0))
    assert ros.spin_until(lambda: len(out) == 1)
    np.testing.assert_array_equal(out[0].data, [0, 1, 0, 0])  # goal in the 90 deg sector
    odom_pub.publish(odom(0.0, x=math.nan))  # NaN pose: logged and skipped
    odom_pub.publish(odom(0.0, frame="map"))  # another frame: logged and skipped
    odom_pub.publish(odom(math.pi / 2))  # facing the goal: 0 deg sector
    assert ros.spin_until(lambda: len(out) == 2)
    np.testing.assert_array_equal(out[1].data, [1, 0, 0, 0])
    assert not ros.spin_until(lambda: len(out) > 2, timeout=0.2)


@pytest.fixture
def arbitrator_files(tmp_path, small_repertoire):
    config = neat_config()
    spec = network_spec(random_genomes(config, 1, seed=5)[0], config)
    arb = ArbitratorFile(
        "evorbc", "4ws-5", spec, LAYOUT, "polar", {"fingerprint": small_repertoire.fingerprint()}
    )
    arb_path, rep_path = tmp_path / "a.json", tmp_path / "r.json"
    arb.save(arb_path)
    small_repertoire.save(rep_path)
    return arb_path, rep_path, Arbitrator(arb, small_repertoire)


def test_arbitrator_node_chooses_once_both_inputs_are_new(ros, arbitrator_files, small_repertoire):
    arb_path, rep_path, offline = arbitrator_files
    ros.make(ArbitratorNode, arbitrator=str(arb_path), repertoire=str(rep_path))
    genes = ros.listen(Float64MultiArray, "evorbc/primitive")
    diag = ros.listen(Float64MultiArray, "evorbc/mapping")
    rf = ros.publisher(Float64MultiArray, "evorbc/rangefinders")
    gs = ros.publisher(Float64MultiArray, "evorbc/goal_sectors")
    ros.connected(rf)
    ros.connected(gs)
    rng = np.random.default_rng(0)
    for k in range(5):
        ranges = rng.uniform(0, 1, 6)
        sectors = np.eye(4)[k % 4]
        rf.publish(vector_message(ranges))
        ros.spin_until(lambda: False, timeout=0.05)
        assert len(genes) == k  # waits for the goal readings of the same cycle
        gs.publish(vector_message(sectors))
        assert ros.spin_until(lambda k=k: len(genes) == k + 1 and len(diag) == k + 1)
        index, _ = offline.choose(np.concatenate([ranges, sectors]))
        assert diag[-1].data[4] == index
        np.testing.assert_array_equal(genes[-1].data, small_repertoire.genes[index])
    rf.publish(vector_message([0.5] * 5))  # wrong length: logged and skipped
    gs.publish(vector_message([1, 0, 0, 0]))
    rf.publish(vector_message([0.5] * 6))
    assert ros.spin_until(lambda: len(genes) == 6)


def test_arbitrator_node_refuses_bad_files(ros, arbitrator_files, tmp_path, small_repertoire):
    arb_path, _, _ = arbitrator_files
    with pytest.raises(StartupError, match="no such arbitrator file"):
        ros.make(ArbitratorNode, arbitrator=str(tmp_path / "missing.json"))
    corrupt = tmp_path / "corrupt.json"
    corrupt.write_text(arb_path.read_text()[:300])
    with pytest.raises(StartupError, match="truncated arbitrator file"):
        ros.make(ArbitratorNode, arbitrator=str(corrupt))
    other = tmp_path / "other.json"
    data = small_repertoire.to_dict()
    data["primitives"] = {k: v[1:] for k, v in data["primitives"].items()}
    import json

    other.write_text(json.dumps(data))
    with pytest.raises(StartupError, match="does not match the arbitrator"):
        ros.make(ArbitratorNode, arbitrator=str(arb_path), repertoire=str(other))
    node = ros.make(
        ArbitratorNode, arbitrator=str(arb_path), repertoire=str(other), allow_mismatch=True
    )
    assert node.controller.warnings


def test_executor_stops_within_a_cycle_of_stale_input_and_resumes(ros):
    node = ros.make(PrimitiveExecutorNode, sim_time=True, robot="4ws-5")
    wheels = ros.listen(Float64MultiArray, "wheel_velocity_controller/commands")
    steering = ros.listen(Float64MultiArray, "steering_position_controller/commands")
    prim, rf, gs = ros.executor_inputs()
    genes = [1.0, 0.5, 0.5, -0.5, -0.5]  # full speed, toe-in steering

    def cycle(t, with_rangefinders=True):
        ros.set_clock(t)
        if with_rangefinders:
            rf.publish(vector_message([0.0] * 6))
        gs.publish(vector_message([1, 0, 0, 0]))
        prim.publish(vector_message(genes))
        seen = node.logic.last_seen
        topics = ["primitive", "evorbc/goal_sectors"]
        topics += ["evorbc/rangefinders"] if with_rangefinders else []
        assert ros.spin_until(
            lambda: all(seen[k] is not None and abs(seen[k] - t) < 1e-6 for k in topics)
        )
        ros.spin_until(lambda: False, timeout=0.02)  # let any reply go out

    t = 1.0
    for _ in range(5):
        cycle(t)
        t += 0.1
    np.testing.assert_allclose(wheels[-1].data, [0.2 / 0.02] * 4)  # 10 rad/s
    np.testing.assert_allclose(steering[-1].data, np.radians([22.5, 22.5, -22.5, -22.5]))
    last_good = t - 0.1
    # The laser goes silent; primitives and goal readings keep coming.
    while t < last_good + 0.3 + 1e-9:
        cycle(t, with_rangefinders=False)
        assert wheels[-1].data[0] != 0.0  # not stale yet: 0.3 s is allowed
        t += 0.1
    cycle(t, with_rangefinders=False)  # first cycle past 0.3 s
    assert list(wheels[-1].data) == [0.0] * 4
    np.testing.assert_allclose(steering[-1].data, np.radians([22.5, 22.5, -22.5, -22.5]))
    t += 0.1
    cycle(t)  # the laser is back: running again at once
    np.testing.assert_allclose(wheels[-1].data, [10.0] * 4)


def test_executor_stops_when_the_arbitrator_falls_silent(ros):
    ros.make(PrimitiveExecutorNode, sim_time=True)
    wheels = ros.listen(Float64MultiArray, "wheel_velocity_controller/commands")
    prim, rf, gs = ros.executor_inputs()
    ros.set_clock(1.0)
    rf.publish(vector_message([0.0] * 6))
    gs.publish(vector_message([1, 0, 0, 0]))
    prim.publish(vector_message([1.0, 0, 0, 0, 0]))
    assert ros.spin_until(lambda: len(wheels) == 1)
    # Sensors keep arriving, the arbitrator says nothing: the timer stops the robot.
    for k in range(1, 6):
        ros.set_clock(1.0 + 0.1 * k)
        rf.publish(vector_message([0.0] * 6))
        gs.publish(vector_message([1, 0, 0, 0]))
        ros.spin_until(lambda: False, timeout=0.05)
    assert wheels[-1].data[0] == 0.0
    stops = [k for k, w in enumerate(wheels) if w.data[0] == 0.0]
    assert stops and stops[0] <= 4  # at the latest on the tick after 0.3 s (t = 1.4 s)


@pytest.mark.parametrize(
    ("cls", "params", "needle"),
    [
        (PrimitiveExecutorNode, {"robot": "tank"}, "parameter robot must be one of"),
        (PrimitiveExecutorNode, {"wheel_radius": -1.0}, "wheel_radius must be between 0.0 and"),
        (LaserSensorNode, {"laser_yaw": math.nan}, "laser_yaw must be a finite"),
        (LaserSensorNode, {"sensor_layout": "/nonexistent.yaml"}, "no such settings file"),
        (RadarSensorNode, {"goal_type": "polygon"}, "goal_type must be"),
        (PrimitiveExecutorNode, {"stale_timeout": "soon"}, "stale_timeout must be a finite"),
        (PrimitiveExecutorNode, {"period": 100.0}, "period must be between 0.001 and 10.0"),
        (PrimitiveExecutorNode, {"watched_inputs": ["scan"]}, "watched_inputs must be made of"),
        (PrimitiveExecutorNode, {"robot": 5}, "parameter robot must be a string"),
    ],
)
def test_bad_parameters_stop_a_node_at_start_up(ros, cls, params, needle):
    with pytest.raises(StartupError, match=needle) as info:
        ros.make(cls, **params)
    assert "\n" not in str(info.value)


def test_a_whole_number_is_accepted_for_a_real_parameter(ros):
    node = ros.make(PrimitiveExecutorNode, robot="hexapod", trajectory_rate=100, period=1)
    assert node.logic.dt == pytest.approx(0.01) and node.period == 1.0


def clock_network(n_inputs: int):
    """A recurrent EvoRBC network whose output m1 counts cycles: output 0 adds 0.05 a cycle
    to itself (a clamped self-loop), output 1 follows the first rangefinder; so the same
    readings give a different mapping point every cycle until a reset."""
    from evorbc_ros.network import ConnectionSpec, NetworkSpec, NodeSpec

    nodes = (NodeSpec(0, 0.05, 1.0, "clamped", "sum"), NodeSpec(1, 0.0, 1.0, "sigmoid", "sum"))
    connections = (ConnectionSpec(0, 0, 1.0), ConnectionSpec(-1, 1, 1.0))
    inputs = tuple(-i - 1 for i in range(n_inputs))
    return NetworkSpec(inputs, (0, 1), nodes, connections, recurrent=True)


def test_the_reset_service_sets_a_recurrent_arbitrators_state_back_to_zero(
    ros, tmp_path, small_repertoire
):
    from std_srvs.srv import Empty

    arb = ArbitratorFile(
        "evorbc",
        "4ws-5",
        clock_network(LAYOUT.n_inputs),
        LAYOUT,
        "polar",
        {"fingerprint": small_repertoire.fingerprint()},
    )
    arb_path, rep_path = tmp_path / "a.json", tmp_path / "r.json"
    arb.save(arb_path)
    small_repertoire.save(rep_path)
    ros.make(ArbitratorNode, arbitrator=str(arb_path), repertoire=str(rep_path))
    diag = ros.listen(Float64MultiArray, "evorbc/mapping")
    rf = ros.publisher(Float64MultiArray, "evorbc/rangefinders")
    gs = ros.publisher(Float64MultiArray, "evorbc/goal_sectors")
    ros.connected(rf)
    ros.connected(gs)
    client = ros.helper.create_client(Empty, "/arbitrator/reset")
    assert ros.spin_until(client.service_is_ready)

    def cycles(n):
        start = len(diag)
        for k in range(n):
            rf.publish(vector_message([0.5] * 6))
            gs.publish(vector_message([1, 0, 0, 0]))
            assert ros.spin_until(lambda k=k: len(diag) == start + k + 1)
        return [d.data[0] for d in diag[start:]]  # m1 of each cycle

    first = cycles(4)
    assert first == pytest.approx([0.05, 0.10, 0.15, 0.20])  # the state carries over
    assert cycles(1) == pytest.approx([0.25])
    future = client.call_async(Empty.Request())
    assert ros.spin_until(future.done)
    assert cycles(4) == first  # back to 0: the same readings give the first outputs again
