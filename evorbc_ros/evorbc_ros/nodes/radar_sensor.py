"""``radar_sensor``: robot pose and goal -> goal-sector (4WS) or goal-bearing readings.

A layout with a motion input (docs/design.md section 5) gets it here too, appended: the
distance moved over its window, timed by the odometry's header stamps (a stamp earlier
than the last, or a new goal, starts the window again; a repeated stamp is logged).

Subscribes ``odom`` (nav_msgs/Odometry, sensor-data QoS) and ``goal``
(geometry_msgs/PointStamped, or PoseStamped with ``goal_type: pose``); publishes
``evorbc/goal_sectors`` (std_msgs/Float64MultiArray, reliable) on every odometry message
once a goal is known. The goal must be in the odometry's frame (no tf here); messages with
NaN poses or another frame are logged and skipped.

The goal is subscribed twice, with one callback: reliable transient-local, so a latched
goal published before this node started still arrives, and reliable volatile, because a
transient-local subscription never matches a volatile publisher (RViz's goal tool,
``ros2 topic pub``). A goal that arrives on both is simply taken twice. RViz's goal tool
publishes a PoseStamped on ``/goal_pose``: ``-p goal_type:=pose -r goal:=/goal_pose``.
Health on ``/diagnostics``; with ``markers`` the lit sectors or the bearing on
``~/markers``.
"""

from __future__ import annotations

import sys

from geometry_msgs.msg import PointStamped, PoseStamped
from nav_msgs.msg import Odometry
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray

from evorbc_ros.goal import GoalInputs, yaw_from_quaternion
from evorbc_ros.health import WARN, Health, Meter, report_input, report_skipped
from evorbc_ros.laser import InputError
from evorbc_ros.marker_geometry import bearing_arrow, sector_wedges
from evorbc_ros.node_parameters import PARAMETERS, REMOVED
from evorbc_ros.nodes.common import (
    LATCHED,
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
from evorbc_ros.nodes.markers import Markers, arrow, triangles
from evorbc_ros.nodes.parameters import ParameterGuard, declare_all

SPECS = PARAMETERS["radar_sensor"]
#: s without odometry before the health report warns.
QUIET = 1.0
#: m, how far the sector wedges and the bearing arrow reach in the markers.
MARKER_RADIUS = 0.5


class RadarSensorNode(Node):
    """Publishes goal-direction readings for every pose."""

    def __init__(self, **kwargs) -> None:
        super().__init__("radar_sensor", **kwargs)
        with logged_startup(self):
            p = declare_all(self, SPECS, "at start-up", REMOVED["radar_sensor"])
            self.layout = load_sensor_layout(p["sensor_layout"])
            try:
                self.inputs = GoalInputs(self.layout)
            except ValueError as e:
                raise StartupError(f"parameter sensor_layout: {e}") from None
        ParameterGuard(self, SPECS, "at start-up")
        self.goal: tuple[float, float, str] | None = None
        self.pub = self.create_publisher(Float64MultiArray, "evorbc/goal_sectors", RELIABLE)
        self.poses, self.skipped = Meter(), Meter()
        self.markers = Markers(self, p["marker_frame"]) if p["markers"] else None
        self.diagnostics = DiagnosticsPublisher(self, p["diagnostics_period"], self.health)
        msg_type = PointStamped if p["goal_type"] == "point" else PoseStamped
        # A volatile publisher is "incompatible" with the latched subscription by design;
        # the volatile one takes its goals, and reports any real mismatch (best effort).
        quiet = SubscriptionEventCallbacks(incompatible_qos=lambda info: None)
        self.goal_subs = [
            self.create_subscription(
                msg_type, "goal", self.on_goal, LATCHED, event_callbacks=quiet
            ),
            self.create_subscription(msg_type, "goal", self.on_goal, RELIABLE),
        ]
        self.odom_sub = self.create_subscription(
            Odometry, "odom", self.on_odom, input_qos(p["input_qos"])
        )

    def on_goal(self, msg) -> None:
        """Remember the goal (point, or a pose's position)."""
        p = msg.point if isinstance(msg, PointStamped) else msg.pose.position
        goal = (p.x, p.y, msg.header.frame_id)
        if goal != self.goal:
            self.get_logger().info(f"goal ({p.x:.3f}, {p.y:.3f}) in frame '{msg.header.frame_id}'")
            self.inputs.reset()  # a new goal, a new run: the motion window starts again
        self.goal = goal

    def on_odom(self, msg: Odometry) -> None:
        """Publish the readings for this pose."""
        topic = self.odom_sub.topic_name
        now = now_seconds(self)
        self.poses.tick(now)
        if self.goal is None:
            self.get_logger().info(
                f"waiting for a goal on {self.goal_subs[1].topic_name}", throttle_duration_sec=5.0
            )
            return
        gx, gy, frame = self.goal
        if frame and msg.header.frame_id and frame != msg.header.frame_id:
            self.skipped.tick(now)
            self.get_logger().warning(
                f"{topic}: frame '{msg.header.frame_id}' differs from the goal's "
                f"'{frame}'; skipped (publish the goal in the odometry frame)",
                throttle_duration_sec=5.0,
            )
            return
        pose = msg.pose.pose
        try:
            q = pose.orientation
            yaw = yaw_from_quaternion(q.x, q.y, q.z, q.w)
            stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            readings = self.inputs.readings(
                pose.position.x, pose.position.y, yaw, gx, gy, stamp_ns=stamp
            )
        except InputError as e:
            self.skipped.tick(now)
            self.get_logger().warning(f"{topic}: skipped a pose: {e}", throttle_duration_sec=2.0)
            return
        if self.inputs.motion is not None and self.inputs.motion.repeated:
            self.get_logger().warning(
                f"{topic}: stamp {stamp} ns repeats the last one; the motion input "
                "needs odometry stamped as it is measured (it reads 0 meanwhile)",
                throttle_duration_sec=5.0,
            )
        self.pub.publish(vector_message(readings, self.inputs.names))
        if self.markers is not None:
            self.publish_markers(readings)

    def publish_markers(self, readings) -> None:
        """The lit goal sectors as wedges, or the goal bearing as an arrow (body frame)."""
        sectors = self.layout.goal_sectors
        out = []
        n = len(sectors.centres) if sectors else 0
        if sectors:
            tris = sector_wedges(sectors, readings[:n], MARKER_RADIUS)
            out.append(triangles("goal_sectors", tris, (0.1, 0.5, 1.0, 0.5)))
        if self.layout.goal_bearing:
            line = bearing_arrow(readings[n], MARKER_RADIUS)
            out.append(arrow("goal_bearing", line, (0.1, 0.5, 1.0, 1.0), 0.03))
        self.markers.publish(out)

    def health(self, now: float) -> Health:
        """Odometry rate and age, the goal, skipped poses."""
        h = Health()
        report_input(h, "odometry", self.poses, now, QUIET)
        report_skipped(h, "odometry", self.skipped, now)
        if self.goal is None:
            h.worse(WARN, "no goal yet")
            h.add("goal", None)
        else:
            h.add("goal", f"({self.goal[0]:.3f}, {self.goal[1]:.3f}) in '{self.goal[2]}'")
        return h


def main(argv=None) -> int:
    """Run the node."""
    return run_node(RadarSensorNode, argv)


if __name__ == "__main__":
    sys.exit(main())
