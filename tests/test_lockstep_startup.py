"""A lockstep bridge starts only with its whole graph, however long the graph takes.

A state sent before a node is there would have to be sent again when it comes, and the
nodes that had answered would answer twice: every later cycle shifts. The bridge used to
start without a node still missing after ``startup_timeout`` (30 s), which a loaded
machine can take to start five processes. It now keeps waiting, warning every
``startup_timeout`` s (docs/design/ros-graph.md, "Start-up"). The bridge runs here in-process, with
this test as the rest of its graph.
"""

import threading

from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64MultiArray

from evorbc_ros.nodes.common import vector_message
from sim_bridge import bridge_node
from sim_bridge.bridge_node import SimBridgeNode

COMMANDS = ("steering_position_controller/commands", "wheel_velocity_controller/commands")


class Lines:
    """Stands in for a node's logger: keeps every line, with its level."""

    def __init__(self):
        self.lines = []

    def __getattr__(self, level):
        return lambda text, **_: self.lines.append((level, text))


def test_a_lockstep_bridge_waits_past_its_startup_timeout_for_the_whole_graph(ros, monkeypatch):
    # The bridge's loop runs until the process is asked to stop; here, until the test is.
    stop = threading.Event()
    monkeypatch.setattr(bridge_node, "running", lambda: not stop.is_set())
    ros.helper.destroy_publisher(ros.clock_pub)  # the bridge is this graph's clock
    bridge = ros.make(SimBridgeNode, maze="gaps", episode_time=0.1, startup_timeout=0.3)
    log = Lines()
    bridge.get_logger = lambda: log
    scans = ros.listen(LaserScan, "scan")  # odom's subscriber and the publishers are late
    run = threading.Thread(target=bridge.run_lockstep)
    try:
        run.start()
        ok = ros.spin_until(lambda: len([1 for lv, _ in log.lines if lv == "warning"]) >= 3)
        assert ok, (log.lines, run.is_alive())
        waited = [t for level, t in log.lines if level == "warning"]
        assert all(t.startswith("still waiting for odom, ") for t in waited), waited
        assert all(t.endswith("a lockstep run starts with its whole graph") for t in waited)
        assert not scans and bridge.world.status().time == 0.0  # no state went out
        ros.listen(Odometry, "odom")
        pubs = [ros.publisher(Float64MultiArray, t) for t in (*COMMANDS, "evorbc/primitive")]
        assert ros.spin_until(lambda: len(scans) == 1)  # the first state, once the graph is whole
        for pub in pubs[:2]:
            pub.publish(vector_message([0.0] * 4))
        run.join(timeout=30.0)
        assert not run.is_alive()
        assert len(bridge.trajectory) == 2  # one step of 0.1 s: the episode
        assert not any(t.startswith("starting without") for _, t in log.lines)
    finally:
        stop.set()
        run.join(timeout=30.0)
        bridge.world.close()
