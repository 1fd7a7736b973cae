"""The laser node in-process: dropouts bridged, refusals logged with their reason, and the
coverage warnings of an offset scanner (issue 18, items 1 and 2)."""

import math

import numpy as np
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64MultiArray

from evorbc_ros.config import config_dir
from evorbc_ros.nodes.laser_sensor import LaserSensorNode

#: The paper's layout (rangefinders every 60 deg from 0), whichever controller ships.
PAPER_LAYOUT = str(config_dir() / "sensors" / "4ws.yaml")


class Log:
    """Stands in for a node's logger: keeps the warnings."""

    def __init__(self):
        self.warnings = []

    def warning(self, text, **_):
        self.warnings.append(text)


def quiet(node):
    """Record the node's warnings and what it publishes instead of sending them."""
    log, sent = Log(), []
    node.get_logger = lambda: log
    node.pub = type("Pub", (), {"publish": lambda self, msg: sent.append(msg)})()
    return log.warnings, sent


def message(ranges, angle_min=-math.pi, increment=None, angle_max=None, range_min=0.0):
    msg = LaserScan()
    msg.angle_min = angle_min
    msg.angle_increment = increment if increment is not None else 2 * math.pi / len(ranges)
    last = angle_min + msg.angle_increment * (len(ranges) - 1)
    msg.angle_max = last if angle_max is None else angle_max
    msg.range_min = range_min
    msg.range_max = 10.0
    msg.ranges = [float(r) for r in ranges]
    return msg


def test_dropouts_are_bridged_through_the_topic(ros):
    ros.make(LaserSensorNode, sensor_layout=PAPER_LAYOUT)
    out = ros.listen(Float64MultiArray, "evorbc/rangefinders")
    pub = ros.publisher(LaserScan, "scan")
    ros.connected(pub)
    ranges = np.full(360, 0.5)
    ranges[[0, 60, 120, 180, 240, 300]] = math.nan  # the beam on every axis is dead
    pub.publish(message(ranges))
    assert ros.spin_until(lambda: len(out) == 1)
    np.testing.assert_allclose(out[0].data, 0.55, atol=1e-6)  # was skipped: never moved


def test_refusals_are_logged_with_their_reason(ros):
    node = ros.make(LaserSensorNode, sensor_layout=PAPER_LAYOUT)
    log, _ = quiet(node)
    node.on_scan(message(np.full(360, 0.01), range_min=0.02))
    node.on_scan(message(np.full(360, 0.5), angle_max=math.pi / 2))
    assert log == [
        "/scan: skipped a scan: no valid beam covers the rangefinder at 0.0 deg (body frame; "
        "a beam counts within 2.5 deg): 360 of the scan's 360 ranges are invalid (0 NaN, 360 "
        "below range_min 0.02 m)",
        "/scan: skipped a scan: the scan has 360 ranges, but angle_min -3.14159 to angle_max "
        "1.5708 rad at angle_increment 0.0174533 rad hold 271 beams; refused, since beam "
        "directions are ambiguous (angle_max must lie within one increment of angle_min + "
        "(ranges - 1) * angle_increment)",
    ]


def test_an_offset_scanner_is_warned_about_once(ros):
    # A 180-deg scanner 0.1 m ahead of the centre sees nothing behind itself.
    node = ros.make(LaserSensorNode, laser_x=0.1, sensor_layout=PAPER_LAYOUT)
    log, out = quiet(node)
    for _ in range(3):
        node.on_scan(message(np.full(181, 0.4), angle_min=-math.pi / 2, increment=math.pi / 180))
    assert len(out) == 3
    assert log == [
        "/scan: the scan never covers the rangefinders at [120.0, 180.0, 240.0] deg (body "
        "frame); they read 0, nothing seen",
        "/scan: the scan covers only part of the rangefinders at 0.0 deg (95% covered), 60.0 "
        "deg (85% covered), 300.0 deg (85% covered) (body frame); walls in the rest are not "
        "seen",
    ]
