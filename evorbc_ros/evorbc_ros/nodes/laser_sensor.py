"""``laser_sensor``: any sensor_msgs/LaserScan -> the arbitrator's rangefinder readings.

Subscribes ``scan`` (LaserScan, sensor-data QoS) and publishes ``evorbc/rangefinders``
(std_msgs/Float64MultiArray, reliable): one reading in [0, 1] per configured rangefinder,
labelled with the input names (docs/laser.md). Invalid beams near a rangefinder are
bridged by the valid beams around them. Malformed scans, scans whose beam count disagrees
with their angles, and scans that leave a rangefinder with no valid beam are logged and
skipped (the input goes stale and the robot stops). Remap the topics to use others
(``-r scan:=/front/scan``). Health on ``/diagnostics``; with ``markers`` the rangefinder
rays on ``~/markers``.
"""

from __future__ import annotations

import sys

from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64MultiArray

from evorbc_ros.health import WARN, Health, Meter, report_input, report_skipped
from evorbc_ros.laser import Coverage, InputError, LaserPose, LaserToRangefinders
from evorbc_ros.marker_geometry import rangefinder_rays, reading_colour
from evorbc_ros.node_parameters import PARAMETERS, REMOVED
from evorbc_ros.nodes.common import (
    RELIABLE,
    StartupError,
    input_qos,
    load_sensor_layout,
    logged_startup,
    now_seconds,
    run_node,
    vector_message,
)
from evorbc_ros.nodes.diagnostics import DiagnosticsPublisher
from evorbc_ros.nodes.markers import Markers, segments
from evorbc_ros.nodes.parameters import ParameterGuard, declare_all

SPECS = PARAMETERS["laser_sensor"]
#: s without a scan before the health report warns (a laser sends 10 Hz or more).
QUIET = 1.0


class LaserSensorNode(Node):
    """Converts each scan into rangefinder readings."""

    def __init__(self, **kwargs) -> None:
        super().__init__("laser_sensor", **kwargs)
        with logged_startup(self):
            p = declare_all(self, SPECS, "at start-up", REMOVED["laser_sensor"])
            layout = load_sensor_layout(p["sensor_layout"])
            if layout.rangefinders is None:
                raise StartupError("parameter sensor_layout: the layout has no rangefinders")
        ParameterGuard(self, SPECS, "at start-up")
        self.layout = layout.rangefinders
        pose = LaserPose(p["laser_x"], p["laser_y"], p["laser_yaw"])
        self.converter = LaserToRangefinders(self.layout, pose)
        self.names = layout.input_names()[: len(self.layout.angles)]
        self.pub = self.create_publisher(Float64MultiArray, "evorbc/rangefinders", RELIABLE)
        self.scans, self.skipped = Meter(), Meter()
        self.coverage = ""  # what the last scan geometry leaves unseen, for the report
        self.warned_span = None  # the last scan geometry checked for unseen rangefinders
        self.markers = Markers(self, p["marker_frame"]) if p["markers"] else None
        self.diagnostics = DiagnosticsPublisher(self, p["diagnostics_period"], self.health)
        self.sub = self.create_subscription(
            LaserScan, "scan", self.on_scan, input_qos(p["input_qos"])
        )

    def on_scan(self, msg: LaserScan) -> None:
        """Publish the readings of one scan, or log why it was skipped."""
        topic = self.sub.topic_name
        now = now_seconds(self)
        self.scans.tick(now)
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
            self.skipped.tick(now)
            self.get_logger().warning(f"{topic}: skipped a scan: {e}", throttle_duration_sec=2.0)
            return
        span = (msg.angle_min, msg.angle_increment, len(msg.ranges))
        if span != self.warned_span:
            self.warned_span = span
            self.warn_coverage(topic, self.converter.coverage(*span))
        self.pub.publish(vector_message(readings, self.names))
        if self.markers is not None:
            rays = rangefinder_rays(self.layout, readings)
            colours = [reading_colour(r) for r in readings]
            self.markers.publish([segments("rangefinders", rays, colours, 0.01)])

    def warn_coverage(self, topic: str, cover: Coverage) -> None:
        """Warn (once per scan span) about rangefinders the scan does not wholly cover."""
        problems = []
        if cover.unseen:
            problems.append(f"rangefinders at {cover.unseen} deg are outside the scan")
            self.get_logger().warning(
                f"{topic}: the scan never covers the rangefinders at {cover.unseen} deg "
                "(body frame); they read 0, nothing seen"
            )
        if cover.partly:
            parts = ", ".join(f"{a} deg ({s:.0%} covered)" for a, s in cover.partly.items())
            problems.append(f"rangefinders at {parts} are partly outside the scan")
            self.get_logger().warning(
                f"{topic}: the scan covers only part of the rangefinders at {parts} (body "
                "frame); walls in the rest are not seen"
            )
        self.coverage = "; ".join(problems)

    def health(self, now: float) -> Health:
        """Scan rate and age, skipped scans, rangefinders the scan does not cover."""
        h = Health()
        report_input(h, "scan", self.scans, now, QUIET)
        report_skipped(h, "scan", self.skipped, now)
        if self.coverage:
            h.worse(WARN, self.coverage)
        h.add("rangefinders", len(self.names))
        return h


def main(argv=None) -> int:
    """Run the node."""
    return run_node(LaserSensorNode, argv)


if __name__ == "__main__":
    sys.exit(main())
