"""Visualization markers for RViz and Foxglove: a node's ``~/markers`` MarkerArray.

Built from the body-frame geometry of :mod:`evorbc_ros.marker_geometry`, in the frame the
node's ``marker_frame`` parameter names (``base_link``). Each marker keeps its namespace
and id, so every message replaces the last one. A node makes a :class:`Markers` only when
its ``markers`` parameter is true: otherwise no publisher exists and nothing is computed.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
from geometry_msgs.msg import Point
from rclpy.node import Node
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from evorbc_ros.nodes.common import RELIABLE

#: s a marker stays shown without an update.
LIFETIME = 1


class Markers:
    """A node's marker publisher on ``~/markers``.

    Args:
        node: the node.
        frame: the frame the markers are in.
        publisher: a publisher to use instead of a new one (a lifecycle node's).

    """

    def __init__(self, node: Node, frame: str, publisher=None) -> None:
        self.node = node
        self.frame = frame
        self.pub = publisher or node.create_publisher(MarkerArray, "~/markers", RELIABLE)

    def publish(self, markers: Iterable[Marker]) -> None:
        """Stamp the markers with the node's clock and frame, and publish them."""
        stamp = self.node.get_clock().now().to_msg()
        msg = MarkerArray(markers=list(markers))
        for m in msg.markers:
            m.header.stamp = stamp
            m.header.frame_id = self.frame
        self.pub.publish(msg)

    def destroy(self) -> None:
        """Remove the publisher."""
        self.node.destroy_publisher(self.pub)


def _point(xy) -> Point:
    return Point(x=float(xy[0]), y=float(xy[1]), z=0.0)


def _marker(ns: str, kind: int, rgba: Sequence[float], scale: Sequence[float]) -> Marker:
    m = Marker(ns=ns, id=0, type=kind, action=Marker.ADD)
    # Gone a second after the last update: a stopped or deactivated node leaves no stale
    # target or rays behind in RViz.
    m.lifetime.sec = LIFETIME
    m.pose.orientation.w = 1.0
    m.scale.x, m.scale.y, m.scale.z = (float(v) for v in scale)
    m.color = ColorRGBA(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])
    return m


def segments(ns: str, lines: np.ndarray, colours: Sequence[Sequence[float]], width: float):
    """A LINE_LIST of ``lines`` ``(n, 2, 2)`` (m), one RGB colour per line."""
    m = _marker(ns, Marker.LINE_LIST, (1.0, 1.0, 1.0, 1.0), (width, 0.0, 0.0))
    m.points = [_point(p) for line in lines for p in line]
    m.colors = [ColorRGBA(r=c[0], g=c[1], b=c[2], a=1.0) for c in colours for _ in (0, 1)]
    return m


def triangles(ns: str, tris: np.ndarray, rgba: Sequence[float]) -> Marker:
    """A TRIANGLE_LIST of ``tris`` ``(k, 3, 2)`` (m); an empty one draws nothing."""
    m = _marker(ns, Marker.TRIANGLE_LIST, rgba, (1.0, 1.0, 1.0))
    m.points = [_point(p) for t in tris for p in t]
    return m


def arrow(ns: str, line: np.ndarray, rgba: Sequence[float], width: float, idx: int = 0):
    """An ARROW from ``line[0]`` to ``line[1]`` (m)."""
    m = _marker(ns, Marker.ARROW, rgba, (width, 2.0 * width, 2.0 * width))
    m.id = idx
    m.points = [_point(line[0]), _point(line[1])]
    return m


def sphere(ns: str, xy: Sequence[float], rgba: Sequence[float], diameter: float) -> Marker:
    """A SPHERE at ``xy`` (m)."""
    m = _marker(ns, Marker.SPHERE, rgba, (diameter, diameter, diameter))
    m.pose.position = _point(xy)
    return m
