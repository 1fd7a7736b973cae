"""``laser_sensor``: any sensor_msgs/LaserScan -> the arbitrator's rangefinder readings.

Subscribes ``scan`` (LaserScan, sensor-data QoS) and publishes ``evorbc/rangefinders``
(std_msgs/Float64MultiArray, reliable): one reading in [0, 1] per configured rangefinder,
labelled with the input names (docs/laser.md). Invalid beams near a rangefinder are
bridged by the valid beams around them. Malformed scans, scans whose beam count disagrees
with their angles, and scans that leave a rangefinder with no valid beam are logged and
skipped (the input goes stale and the robot stops).
"""

from __future__ import annotations

import sys

from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64MultiArray

from evorbc_ros.laser import Coverage, InputError, LaserPose, LaserToRangefinders
from evorbc_ros.nodes.common import (
    RELIABLE,
    SENSOR_DATA,
    StartupError,
    declare,
    finite_parameter,
    logged_startup,
    run_node,
    sensor_layout_parameter,
    vector_message,
)


class LaserSensorNode(Node):
    """Converts each scan into rangefinder readings."""

    def __init__(self, **kwargs) -> None:
        super().__init__("laser_sensor", **kwargs)
        with logged_startup(self):
            layout = sensor_layout_parameter(self)
            if layout.rangefinders is None:
                raise StartupError("parameter sensor_layout: the layout has no rangefinders")
            pose = LaserPose(
                finite_parameter(self, "laser_x", 0.0, "scanner position on the robot, x (m)"),
                finite_parameter(self, "laser_y", 0.0, "scanner position on the robot, y (m)"),
                finite_parameter(self, "laser_yaw", 0.0, "scanner yaw in the robot frame (rad)"),
            )
            self.scan_topic = declare(self, "scan_topic", "scan", "input LaserScan topic")
            out_topic = declare(
                self, "output_topic", "evorbc/rangefinders", "output topic (Float64MultiArray)"
            )
        self.converter = LaserToRangefinders(layout.rangefinders, pose)
        n = len(layout.rangefinders.angles)
        self.names = layout.input_names()[:n]
        self.pub = self.create_publisher(Float64MultiArray, out_topic, RELIABLE)
        self.warned_span = None  # the last scan geometry checked for unseen rangefinders
        self.sub = self.create_subscription(LaserScan, self.scan_topic, self.on_scan, SENSOR_DATA)

    def on_scan(self, msg: LaserScan) -> None:
        """Publish the readings of one scan, or log why it was skipped."""
        topic = self.sub.topic_name
        try:
            readings = self.converter.readings(
                msg.angle_min,
                msg.angle_increment,
                msg.ranges,
                msg.range_min,
                msg.range_max,
                angle_max=msg.angle_max,
            )
        except InputError as e:
            self.get_logger().warning(f"{topic}: skipped a scan: {e}", throttle_duration_sec=2.0)
            return
        span = (msg.angle_min, msg.angle_increment, len(msg.ranges))
        if span != self.warned_span:
            self.warned_span = span
            self.warn_coverage(topic, self.converter.coverage(*span))
        self.pub.publish(vector_message(readings, self.names))

    def warn_coverage(self, topic: str, cover: Coverage) -> None:
        """Warn (once per scan span) about rangefinders the scan does not wholly cover."""
        if cover.unseen:
            self.get_logger().warning(
                f"{topic}: the scan never covers the rangefinders at {cover.unseen} deg "
                "(body frame); they read 0, nothing seen"
            )
        if cover.partly:
            parts = ", ".join(f"{a} deg ({s:.0%} covered)" for a, s in cover.partly.items())
            self.get_logger().warning(
                f"{topic}: the scan covers only part of the rangefinders at {parts} (body "
                "frame); walls in the rest are not seen"
            )


def main(argv=None) -> int:
    """Run the node."""
    return run_node(LaserSensorNode, argv)


if __name__ == "__main__":
    sys.exit(main())
