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
"""

from __future__ import annotations

import sys

from geometry_msgs.msg import PointStamped, PoseStamped
from nav_msgs.msg import Odometry
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray

from evorbc_ros.goal import GoalInputs, yaw_from_quaternion
from evorbc_ros.laser import InputError
from evorbc_ros.nodes.common import (
    LATCHED,
    RELIABLE,
    SENSOR_DATA,
    StartupError,
    declare,
    logged_startup,
    run_node,
    sensor_layout_parameter,
    vector_message,
)


class RadarSensorNode(Node):
    """Publishes goal-direction readings for every pose."""

    def __init__(self, **kwargs) -> None:
        super().__init__("radar_sensor", **kwargs)
        with logged_startup(self):
            layout = sensor_layout_parameter(self)
            try:
                self.inputs = GoalInputs(layout)
            except ValueError as e:
                raise StartupError(f"parameter sensor_layout: {e}") from None
            self.odom_topic = declare(self, "odom_topic", "odom", "input Odometry topic")
            self.goal_topic = declare(
                self, "goal_topic", "goal", "goal topic (latched or volatile publishers)"
            )
            goal_type = declare(self, "goal_type", "point", "goal message type: point or pose")
            if goal_type not in ("point", "pose"):
                raise StartupError(
                    f"parameter goal_type must be 'point' or 'pose', got {goal_type!r}"
                )
            out_topic = declare(
                self, "output_topic", "evorbc/goal_sectors", "output topic (Float64MultiArray)"
            )
        self.goal: tuple[float, float, str] | None = None
        self.pub = self.create_publisher(Float64MultiArray, out_topic, RELIABLE)
        msg_type = PointStamped if goal_type == "point" else PoseStamped
        # A volatile publisher is "incompatible" with the latched subscription by design;
        # the volatile one takes its goals, and reports any real mismatch (best effort).
        quiet = SubscriptionEventCallbacks(incompatible_qos=lambda info: None)
        self.goal_subs = [
            self.create_subscription(
                msg_type, self.goal_topic, self.on_goal, LATCHED, event_callbacks=quiet
            ),
            self.create_subscription(msg_type, self.goal_topic, self.on_goal, RELIABLE),
        ]
        self.odom_sub = self.create_subscription(
            Odometry, self.odom_topic, self.on_odom, SENSOR_DATA
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
        if self.goal is None:
            self.get_logger().info(
                f"waiting for a goal on {self.goal_topic}", throttle_duration_sec=5.0
            )
            return
        gx, gy, frame = self.goal
        if frame and msg.header.frame_id and frame != msg.header.frame_id:
            self.get_logger().warning(
                f"{self.odom_topic}: frame '{msg.header.frame_id}' differs from the goal's "
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
            self.get_logger().warning(
                f"{self.odom_topic}: skipped a pose: {e}", throttle_duration_sec=2.0
            )
            return
        if self.inputs.motion is not None and self.inputs.motion.repeated:
            self.get_logger().warning(
                f"{self.odom_topic}: stamp {stamp} ns repeats the last one; the motion input "
                "needs odometry stamped as it is measured (it reads 0 meanwhile)",
                throttle_duration_sec=5.0,
            )
        self.pub.publish(vector_message(readings, self.inputs.names))


def main(argv=None) -> int:
    """Run the node."""
    return run_node(RadarSensorNode, argv)


if __name__ == "__main__":
    sys.exit(main())
