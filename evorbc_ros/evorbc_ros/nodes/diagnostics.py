"""A node's ``/diagnostics`` publisher: its :class:`~evorbc_ros.health.Health` at 1 Hz.

diagnostic_msgs/DiagnosticArray on the absolute topic ``/diagnostics``, where
diagnostic_aggregator, ``rqt_robot_monitor`` and Foxglove look. The timer runs on the
steady (wall) clock: with ``use_sim_time`` in a lockstep run, simulated time may pass ten
times faster, or stand still while the graph waits, and the report must still come once a
wall second. One status per node, named by its fully qualified name, with the robot as
hardware id (docs/design.md section 9).
"""

from __future__ import annotations

from collections.abc import Callable

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.clock import Clock, ClockType
from rclpy.node import Node

from evorbc_ros.health import Health
from evorbc_ros.nodes.common import RELIABLE, now_seconds

LEVELS = {0: DiagnosticStatus.OK, 1: DiagnosticStatus.WARN, 2: DiagnosticStatus.ERROR}


class DiagnosticsPublisher:
    """Publishes ``report(now)`` every ``period`` wall seconds.

    Args:
        node: the node reporting.
        period: s of wall time between reports.
        report: the node's health at ``now`` (s, node clock).
        hardware_id: what the node drives (the robot's name), or "".

    """

    def __init__(
        self, node: Node, period: float, report: Callable[[float], Health], hardware_id: str = ""
    ) -> None:
        self.node = node
        self.report = report
        self.hardware_id = hardware_id
        self.name = node.get_fully_qualified_name()
        self.pub = node.create_publisher(DiagnosticArray, "/diagnostics", RELIABLE)
        self.timer = node.create_timer(
            period, self.publish, clock=Clock(clock_type=ClockType.STEADY_TIME)
        )

    def publish(self) -> None:
        """One DiagnosticArray with this node's status."""
        health = self.report(now_seconds(self.node))
        msg = DiagnosticArray()
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.status = [
            DiagnosticStatus(
                level=LEVELS[health.level],
                name=self.name,
                message=health.message,
                hardware_id=self.hardware_id,
                values=[KeyValue(key=k, value=v) for k, v in health.values.items()],
            )
        ]
        self.pub.publish(msg)

    def destroy(self) -> None:
        """Stop reporting (the node is going away)."""
        self.node.destroy_timer(self.timer)
        self.node.destroy_publisher(self.pub)
