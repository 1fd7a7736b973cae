"""In-process ROS 2 test support: one Context and executor per test, hermetic discovery.

Nothing sleeps blindly: :meth:`Ros.spin_until` spins the executor until a condition holds
or a deadline passes.
"""

import contextlib
import gc
import time

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock

from evorbc_ros.nodes.common import RELIABLE


class Ros:
    """A context, an executor and the nodes of one test."""

    def __init__(self, context):
        self.context = context
        self.executor = SingleThreadedExecutor(context=context)
        self.nodes = []
        self.helper = self.add(Node("test_helper", context=context))
        self.clock_pub = self.helper.create_publisher(Clock, "/clock", RELIABLE)

    def add(self, node):
        """Register a node with the executor (and for clean-up)."""
        self.nodes.append(node)
        self.executor.add_node(node)
        return node

    def make(self, cls, sim_time=False, namespace=None, **params):
        """Construct a node class with parameter overrides in this context."""
        overrides = [Parameter(k, value=v) for k, v in params.items()]
        if sim_time:
            overrides.append(Parameter("use_sim_time", value=True))
        extra = {} if namespace is None else {"namespace": namespace}
        return self.add(cls(context=self.context, parameter_overrides=overrides, **extra))

    def spin_until(self, condition, timeout=5.0):
        """Spin until ``condition()`` is true; False if ``timeout`` seconds pass first."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if condition():
                return True
            self.executor.spin_once(timeout_sec=0.01)
        return condition()

    def listen(self, msg_type, topic, qos=RELIABLE):
        """Collect every message on ``topic`` into a list."""
        got = []
        self.helper.create_subscription(msg_type, topic, got.append, qos)
        return got

    def publisher(self, msg_type, topic, qos=RELIABLE):
        """A publisher on the helper node."""
        return self.helper.create_publisher(msg_type, topic, qos)

    def connected(self, publisher, count=1, timeout=5.0):
        """Wait until ``publisher`` has ``count`` subscribers."""
        assert self.spin_until(lambda: publisher.get_subscription_count() >= count, timeout)

    def arbitrator_inputs(self):
        """Connected publishers of the arbitrator's inputs: rangefinders, goal sectors."""
        from std_msgs.msg import Float64MultiArray

        pubs = [
            self.publisher(Float64MultiArray, t)
            for t in ("evorbc/rangefinders", "evorbc/goal_sectors")
        ]
        for p in pubs:
            self.connected(p)
        return pubs

    def executor_inputs(self):
        """Connected publishers of the executor's inputs: primitive, rangefinders, goal."""
        from std_msgs.msg import Float64MultiArray

        pubs = [
            self.publisher(Float64MultiArray, t)
            for t in ("evorbc/primitive", "evorbc/rangefinders", "evorbc/goal_sectors")
        ]
        for p in pubs:
            self.connected(p)
        return pubs

    def set_clock(self, seconds):
        """Publish simulated time and let the nodes see it."""
        from sim_bridge.bridge_node import stamp

        self.clock_pub.publish(Clock(clock=stamp(seconds)))
        target = round(seconds * 1e9)
        assert self.spin_until(
            lambda: all(
                n.get_clock().now().nanoseconds >= target
                for n in self.nodes
                if n.get_parameter("use_sim_time").value
            )
        )

    def close(self):
        """Destroy the nodes and shut the context down."""
        self.executor.shutdown()
        for n in self.nodes:
            n.destroy_node()
        rclpy.try_shutdown(context=self.context)


@contextlib.contextmanager
def ros_with_args(*args):
    """A :class:`Ros` whose context has ``--ros-args args`` (parameter files, remappings).

    Set ``ROS_AUTOMATIC_DISCOVERY_RANGE=OFF`` first (the ``ros`` fixture does).
    """
    # A node whose constructor raised in an earlier test (a start-up error) is never
    # destroyed explicitly; the exception's traceback keeps it in a reference cycle until
    # the garbage collector runs. While it lives, rcl sends every log line of a node of the
    # same name over its /rosout publisher, in its old context, so a new node's start-up
    # line would never reach this test's /rosout. Collect it first.
    gc.collect()
    context = rclpy.Context()
    rclpy.init(context=context, args=["--ros-args", *args] if args else None)
    r = Ros(context)
    try:
        yield r
    finally:
        r.close()


@pytest.fixture
def ros(monkeypatch):
    """A hermetic in-process ROS 2 setup (no discovery outside this process)."""
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    with ros_with_args() as r:
        yield r
