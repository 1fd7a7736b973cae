"""Visualization markers: the geometry (pure), and the nodes publish them only when asked.

docs/design.md section 9, "Markers": in the robot's frame, the rangefinder rays with their
readings (laser_sensor), the lit goal sectors (radar_sensor), the mapping's target point and
the chosen primitive's expected displacement (arbitrator). With ``markers`` false (the
default) no publisher exists and nothing is computed.
"""

import math

import numpy as np
import pytest
from geometry_msgs.msg import PointStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64MultiArray
from visualization_msgs.msg import Marker, MarkerArray

from evorbc_ros.defaults import default_repertoire
from evorbc_ros.marker_geometry import (
    bearing_arrow,
    primitive_arrows,
    rangefinder_rays,
    reading_colour,
    sector_wedges,
)
from evorbc_ros.nodes.arbitrator import ArbitratorNode
from evorbc_ros.nodes.common import LATCHED, vector_message
from evorbc_ros.nodes.laser_sensor import LaserSensorNode
from evorbc_ros.nodes.radar_sensor import RadarSensorNode
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.sensors import GoalSectorLayout, RangefinderLayout


def test_a_ray_reaches_as_far_as_its_reading_says():
    layout = RangefinderLayout(angles=(0.0, math.pi / 2), max_range=2.0, mount_radius=0.1)
    rays = rangefinder_rays(layout, np.array([0.0, 0.75]))
    np.testing.assert_allclose(rays[0], [[0.1, 0.0], [2.1, 0.0]], atol=1e-12)  # nothing seen
    np.testing.assert_allclose(rays[1], [[0.0, 0.1], [0.0, 0.6]], atol=1e-12)  # 0.5 m away
    assert reading_colour(0.0) == (0.0, 1.0, 0.0) and reading_colour(1.0) == (1.0, 0.0, 0.0)


def test_only_lit_sectors_are_filled_within_their_edges():
    layout = GoalSectorLayout(centres=(0.0, math.pi / 2, math.pi, -math.pi / 2), width=math.pi / 2)
    tris = sector_wedges(layout, np.array([0.0, 1.0, 0.0, 0.0]), radius=0.5, steps=4)
    assert tris.shape == (4, 3, 2)
    angles = np.arctan2(tris[:, 1:, 1], tris[:, 1:, 0])
    assert angles.min() == pytest.approx(math.pi / 4) and angles.max() == pytest.approx(
        3 * math.pi / 4
    )
    assert np.allclose(np.hypot(*tris[:, 1:].reshape(-1, 2).T), 0.5)
    assert sector_wedges(layout, np.zeros(4), 0.5).shape == (0, 3, 2)


def test_the_bearing_and_the_primitive_arrows_point_where_they_should():
    np.testing.assert_allclose(bearing_arrow(0.5, 1.0)[1], [1.0, 0.0], atol=1e-12)  # ahead
    np.testing.assert_allclose(bearing_arrow(0.75, 1.0)[1], [0.0, 1.0], atol=1e-12)  # left
    move, turn = primitive_arrows((0.3, -0.1), math.pi / 2, 0.1)
    np.testing.assert_allclose(move, [[0, 0], [0.3, -0.1]])
    np.testing.assert_allclose(turn, [[0.3, -0.1], [0.3, 0.0]], atol=1e-12)


def marker_arrays(ros, node):
    return ros.listen(MarkerArray, f"/{node}/markers")


def test_no_markers_means_no_publisher(ros):
    for cls, name in ((LaserSensorNode, "laser_sensor"), (RadarSensorNode, "radar_sensor")):
        node = ros.make(cls)
        assert node.markers is None
        assert node.count_publishers(f"/{name}/markers") == 0
    node = ros.make(ArbitratorNode)
    assert node.markers is None and node.count_publishers("/arbitrator/markers") == 0


def test_the_laser_node_draws_its_rangefinder_rays(ros):
    node = ros.make(LaserSensorNode, markers=True, marker_frame="base_footprint")
    got = marker_arrays(ros, "laser_sensor")
    readings = ros.listen(Float64MultiArray, "evorbc/rangefinders")
    pub = ros.publisher(LaserScan, "scan")
    ros.connected(pub)
    msg = LaserScan()
    msg.angle_min, msg.angle_increment = -math.pi, 2 * math.pi / 360
    msg.angle_max = msg.angle_min + msg.angle_increment * 359
    msg.range_max = 10.0
    msg.ranges = [1.0] * 360
    pub.publish(msg)
    assert ros.spin_until(lambda: got and readings)
    (lines,) = got[-1].markers
    assert lines.type == Marker.LINE_LIST and lines.header.frame_id == "base_footprint"
    n = len(node.layout.angles)
    assert len(lines.points) == 2 * n and len(lines.colors) == 2 * n
    expected = rangefinder_rays(node.layout, np.asarray(readings[-1].data))
    ends = np.array([[p.x, p.y] for p in lines.points[1::2]])
    np.testing.assert_allclose(ends, expected[:, 1], atol=1e-9)


def test_the_radar_node_draws_the_lit_sector(ros):
    node = ros.make(RadarSensorNode, markers=True)
    got = marker_arrays(ros, "radar_sensor")
    odom = ros.publisher(Odometry, "odom")
    goal = ros.publisher(PointStamped, "goal", LATCHED)
    ros.connected(odom)
    target = PointStamped()
    target.point.x = 3.0  # straight ahead
    goal.publish(target)
    assert ros.spin_until(lambda: node.goal is not None)
    pose = Odometry()
    pose.pose.pose.orientation.w = 1.0
    odom.publish(pose)
    assert ros.spin_until(lambda: got)
    wedges = next(m for m in got[-1].markers if m.ns == "goal_sectors")
    assert wedges.type == Marker.TRIANGLE_LIST and len(wedges.points) > 0
    xs = [p.x for p in wedges.points]
    assert min(xs) >= -1e-9  # the sector ahead only


def test_the_arbitrator_draws_the_target_and_the_chosen_primitive(ros):
    ros.make(ArbitratorNode, markers=True)
    got = marker_arrays(ros, "arbitrator")
    mapping = ros.listen(Float64MultiArray, "evorbc/mapping")
    rf, gs = ros.arbitrator_inputs()
    rf.publish(vector_message([0.0] * 8))
    gs.publish(vector_message([1.0] + [0.0] * 8))
    assert ros.spin_until(lambda: got and mapping)
    _, _, x, y, index = mapping[-1].data
    markers = {(m.ns, m.id): m for m in got[-1].markers}
    target = markers["mapping_target", 0]
    assert (target.pose.position.x, target.pose.position.y) == (x, y)
    move = markers["primitive", 0]
    behaviour = Repertoire.load(default_repertoire("4ws-5")).behaviour[int(index)]
    assert (move.points[1].x, move.points[1].y) == tuple(behaviour)
