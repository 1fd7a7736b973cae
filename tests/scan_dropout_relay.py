"""Test and bench node: relays ``scan`` to ``scan_dropped`` with beams knocked out.

Knocks out (NaN) each beam independently with probability ``dropout`` (seeded by
``seed``), and every beam whose direction lies in ``dead_sector`` ([lo, hi] deg, scanner
frame; empty for none), as dust, glass or the robot's own mast do to a real lidar. Counts
the scans it relays and the rangefinder readings the laser node publishes
(``evorbc/rangefinders``), and writes both to ``count_file`` (JSON) as it goes and at exit.

It subscribes to ``scan`` only once the laser node listens to ``scan_dropped``, so a
lockstep bridge (which waits for a ``scan`` subscriber) never sends its first scan into
an unconnected relay. Not a product node: run with
``python tests/scan_dropout_relay.py --ros-args -p dropout:=0.05 ...``.
"""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64MultiArray

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.nodes.common import RELIABLE


class ScanDropoutRelay(Node):
    """``scan`` -> ``scan_dropped`` with dropouts; counts scans and readings."""

    def __init__(self) -> None:
        super().__init__("scan_dropout_relay")
        self.dropout = float(self.declare_parameter("dropout", 0.0).value)
        sector = list(self.declare_parameter("dead_sector", [0.0, 0.0]).value)
        self.sector = [math.radians(v) for v in sector] if sector[1] > sector[0] else None
        self.rng = np.random.default_rng(int(self.declare_parameter("seed", 0).value))
        self.count_file = str(self.declare_parameter("count_file", "").value)
        self.counts = {"scans": 0, "readings": 0, "dropped_beams": 0, "beams": 0}
        self.pub = self.create_publisher(LaserScan, "scan_dropped", RELIABLE)
        self.create_subscription(
            Float64MultiArray, "evorbc/rangefinders", self.on_readings, RELIABLE
        )
        self.sub = None
        self.wait = self.create_timer(0.05, self.connect)

    def connect(self) -> None:
        """Subscribe to ``scan`` once the laser node is connected both ways."""
        listening = self.pub.get_subscription_count() > 0
        if listening and self.count_publishers("evorbc/rangefinders") > 0 and self.sub is None:
            self.sub = self.create_subscription(LaserScan, "scan", self.on_scan, RELIABLE)
            self.wait.cancel()

    def on_scan(self, msg: LaserScan) -> None:
        r = np.asarray(msg.ranges, dtype=np.float32)
        dead = self.rng.random(r.size) < self.dropout
        if self.sector is not None:
            angle = msg.angle_min + msg.angle_increment * np.arange(r.size)
            lo, hi = self.sector
            dead |= np.mod(angle - lo, 2 * math.pi) <= hi - lo
        r[dead] = np.nan
        msg.ranges = r.tolist()
        self.counts["scans"] += 1
        self.counts["beams"] += int(r.size)
        self.counts["dropped_beams"] += int(dead.sum())
        self.pub.publish(msg)
        if self.counts["scans"] % 50 == 0:
            self.save()

    def on_readings(self, msg: Float64MultiArray) -> None:
        self.counts["readings"] += 1

    def save(self) -> None:
        if self.count_file:
            atomic_write_text(self.count_file, json.dumps(self.counts))


def main(argv=None) -> int:
    rclpy.init(args=argv)
    node = ScanDropoutRelay()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        node.save()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
