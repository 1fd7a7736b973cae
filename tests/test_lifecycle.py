"""The arbitrator and the executor as lifecycle nodes (docs/design.md section 9).

configure loads and checks the files, activate starts commanding (at once on what came
meanwhile), deactivate stops the robot, cleanup releases; ``autostart`` (default) does
configure and activate at start-up, and a failed configure is then the one FATAL line.
"""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import rclpy
from graph_helpers import graph_env
from lifecycle_msgs.msg import State
from lifecycle_msgs.srv import ChangeState, GetState
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.lifecycle import TransitionCallbackReturn
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray

from evorbc_ros.defaults import default_arbitrator
from evorbc_ros.nodes.arbitrator import ArbitratorNode
from evorbc_ros.nodes.common import RELIABLE, StartupError, vector_message
from evorbc_ros.nodes.primitive_executor import PrimitiveExecutorNode

SUCCESS, FAILURE = TransitionCallbackReturn.SUCCESS, TransitionCallbackReturn.FAILURE
SHIPPED = default_arbitrator("4ws-5")  # 8 rangefinders, 8 sectors and motion: 17 inputs


def test_autostart_configures_and_activates(ros):
    node = ros.make(ArbitratorNode)
    assert node.state == "active" and node.controller is not None


def test_without_autostart_the_node_waits_unconfigured_and_commands_nothing(ros):
    node = ros.make(ArbitratorNode, autostart=False)
    assert node.state == "unconfigured" and node.controller is None
    assert node.count_publishers("evorbc/primitive") == 0  # made at configure
    assert node.trigger_configure() == SUCCESS and node.state == "inactive"
    assert node.count_publishers("evorbc/primitive") == 1


def test_a_failed_configure_leaves_the_node_unconfigured_until_fixed(ros, tmp_path):
    missing = tmp_path / "missing.json"
    node = ros.make(ArbitratorNode, autostart=False, arbitrator=str(missing))
    assert node.trigger_configure() == FAILURE
    assert node.state == "unconfigured"
    assert node.configure_error == f"{missing}: no such arbitrator file"
    health = node.health(0.0)
    assert (
        health.level == 2
        and health.message == f"cannot configure: {missing}: no such arbitrator file"
    )
    from rclpy.parameter import Parameter

    assert node.set_parameters([Parameter("arbitrator", value=str(SHIPPED))])[0].successful
    assert node.trigger_configure() == SUCCESS


def test_with_autostart_a_failed_configure_is_the_start_up_error(ros, tmp_path):
    missing = tmp_path / "missing.json"
    with pytest.raises(StartupError, match=f"{missing}: no such arbitrator file"):
        ros.make(ArbitratorNode, arbitrator=str(missing))


def test_activation_chooses_at_once_from_readings_that_came_while_inactive(ros):
    node = ros.make(ArbitratorNode, autostart=False)
    node.trigger_configure()
    genes = ros.listen(Float64MultiArray, "evorbc/primitive")
    rf, gs = ros.arbitrator_inputs()
    rf.publish(vector_message([0.0] * 8))
    gs.publish(vector_message([1.0] + [0.0] * 8))
    assert ros.spin_until(lambda: all(node.groups.fresh.values()))
    ros.spin_until(lambda: False, timeout=0.2)
    assert genes == []  # inactive: held, not chosen
    assert node.trigger_activate() == SUCCESS
    assert ros.spin_until(lambda: len(genes) == 1)
    assert len(genes[0].data) == 5


def test_deactivation_stops_the_robot_and_then_nothing_is_sent(ros):
    # Simulated time that stands still: no keep-alive command, no stale stop, under any load.
    arbitrator = ros.make(ArbitratorNode, sim_time=True)
    executor = ros.make(PrimitiveExecutorNode, sim_time=True)
    ros.set_clock(1.0)
    genes = ros.listen(Float64MultiArray, "evorbc/primitive")
    wheels = ros.listen(Float64MultiArray, "wheel_velocity_controller/commands")
    rf, gs = ros.arbitrator_inputs()
    ros.connected(rf, count=2)  # the arbitrator's and the executor's subscriptions
    rf.publish(vector_message([0.0] * 8))
    gs.publish(vector_message([1.0] + [0.0] * 8))
    assert ros.spin_until(lambda: len(genes) == 1 and len(wheels) >= 1)
    assert arbitrator.trigger_deactivate() == SUCCESS
    assert ros.spin_until(lambda: len(genes) == 2)
    assert list(genes[1].data) == []  # "no primitive": the executor stops at once
    assert ros.spin_until(lambda: wheels[-1].data.tolist() == [0.0] * 4)
    before = len(wheels)
    assert executor.trigger_deactivate() == SUCCESS
    assert ros.spin_until(lambda: len(wheels) > before)  # the stop it sends
    assert list(wheels[-1].data) == [0.0] * 4
    sent = len(wheels)
    ros.spin_until(lambda: False, timeout=0.5)  # several timer periods
    assert len(wheels) == sent  # inactive: nothing more


def test_an_executor_that_never_commanded_sends_nothing_when_deactivated(ros):
    executor = ros.make(PrimitiveExecutorNode)
    wheels = ros.listen(Float64MultiArray, "wheel_velocity_controller/commands")
    assert executor.trigger_deactivate() == SUCCESS
    ros.spin_until(lambda: False, timeout=0.3)
    assert wheels == []  # another node (teleop) may be driving the robot


def test_cleanup_releases_and_configure_loads_again(ros, tmp_path):
    record = tmp_path / "choices.jsonl"
    node = ros.make(ArbitratorNode, record_file=str(record))
    assert node.record is not None
    assert node.trigger_deactivate() == SUCCESS and node.trigger_cleanup() == SUCCESS
    assert node.state == "unconfigured" and node.controller is None and node.record is None
    assert node.count_subscribers("evorbc/rangefinders") == 0
    assert node.trigger_configure() == SUCCESS and node.trigger_activate() == SUCCESS
    assert node.count_subscribers("evorbc/rangefinders") == 1


def test_ros2_lifecycle_sees_the_nodes_through_their_services(ros):
    ros.make(ArbitratorNode, autostart=False)
    ros.make(PrimitiveExecutorNode)
    for name, expected in (
        ("arbitrator", State.PRIMARY_STATE_UNCONFIGURED),
        ("primitive_executor", State.PRIMARY_STATE_ACTIVE),
    ):
        client = ros.helper.create_client(GetState, f"/{name}/get_state")
        assert client.wait_for_service(timeout_sec=5.0)
        future = client.call_async(GetState.Request())
        assert ros.spin_until(future.done)
        assert future.result().current_state.id == expected
    change = ros.helper.create_client(ChangeState, "/arbitrator/change_state")
    request = ChangeState.Request()
    request.transition.id = 1  # configure
    future = change.call_async(request)
    assert ros.spin_until(future.done) and future.result().success


def test_an_active_executor_commands_a_primitive_that_came_while_inactive(ros):
    executor = ros.make(PrimitiveExecutorNode, sim_time=True, autostart=False)
    ros.set_clock(1.0)  # and it stands still: the primitive cannot go stale meanwhile
    executor.trigger_configure()
    wheels = ros.listen(Float64MultiArray, "wheel_velocity_controller/commands")
    prim, rf, gs = ros.executor_inputs()
    rf.publish(vector_message([0.0] * 6))
    gs.publish(vector_message([1, 0, 0, 0]))
    prim.publish(vector_message([1.0, 0, 0, 0, 0]))
    assert ros.spin_until(lambda: executor.primitive_seen)
    assert wheels == []
    assert executor.trigger_activate() == SUCCESS
    assert ros.spin_until(lambda: len(wheels) == 1)
    np.testing.assert_allclose(wheels[0].data, [0.2 / 0.02] * 4)


def test_ctrl_c_stops_the_robot_before_the_executor_exits(tmp_path):
    """The last command of an executor process stopped by SIGINT is the stop (zero speed)."""
    domain = 185
    proc = subprocess.Popen(
        [sys.executable, "-P", "-m", "evorbc_ros.nodes.primitive_executor"],
        env=graph_env(domain),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    context = Context()
    rclpy.init(context=context, domain_id=domain)
    try:
        node = Node("ctrl_c_probe", context=context)
        spin = SingleThreadedExecutor(context=context)
        spin.add_node(node)
        wheels = []
        node.create_subscription(
            Float64MultiArray, "wheel_velocity_controller/commands", wheels.append, RELIABLE
        )
        pubs = [
            node.create_publisher(Float64MultiArray, t, RELIABLE)
            for t in ("evorbc/rangefinders", "evorbc/goal_sectors", "evorbc/primitive")
        ]
        deadline = time.monotonic() + 60
        while (not wheels or wheels[-1].data[0] == 0.0) and time.monotonic() < deadline:
            if proc.poll() is not None:
                break
            pubs[0].publish(vector_message([0.0] * 6))
            pubs[1].publish(vector_message([1, 0, 0, 0]))
            pubs[2].publish(vector_message([1.0, 0, 0, 0, 0]))  # full speed
            spin.spin_once(timeout_sec=0.05)
        assert wheels and wheels[-1].data[0] > 0.0, proc.poll()
        sent = len(wheels)
        os.kill(proc.pid, signal.SIGINT)
        while proc.poll() is None and time.monotonic() < deadline:
            spin.spin_once(timeout_sec=0.05)
        for _ in range(20):  # what is still on its way
            spin.spin_once(timeout_sec=0.05)
        out = proc.communicate(timeout=30)[0]
    finally:
        if proc.poll() is None:
            proc.kill()
        context.try_shutdown()
    assert proc.returncode == 0, out
    assert len(wheels) > sent and list(wheels[-1].data) == [0.0] * 4
    assert "deactivated: robot stopped" in out


def test_an_unexpected_error_in_a_transition_is_said_and_fails_it(ros, monkeypatch):
    def broken(self, *args):
        raise RuntimeError("boom")

    node = ros.make(ArbitratorNode, autostart=False)
    node.trigger_configure()
    monkeypatch.setattr(ArbitratorNode, "activate", broken)
    assert node.trigger_activate() == FAILURE
    assert node.state == "inactive" and node.configure_error == "RuntimeError: boom"
    monkeypatch.setattr(ArbitratorNode, "configure", broken)
    with pytest.raises(StartupError, match="RuntimeError: boom"):
        ros.make(ArbitratorNode)  # autostart: the one FATAL start-up line says it
