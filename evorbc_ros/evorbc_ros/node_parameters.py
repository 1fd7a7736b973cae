"""The evorbc nodes' parameters as data: name, default, range, unit and meaning (pure code).

One table per node. The nodes declare their parameters from it, with the range in the
descriptor (``ros2 param describe``) and the same check for an override at start-up and
for ``ros2 param set``; the tests check the shipped parameter files (``config/ros/``)
against it without ROS (docs/design.md section 9, "Parameters").

Topic names are not parameters: every topic has a fixed relative name, changed by
remapping (``--ros-args -r scan:=/front/scan``). :data:`REMOVED` lists the topic-name
parameters of earlier versions with the remapping that replaces each.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: Largest integer parameter (ROS parameters are int64).
INT64_MAX = 2**63 - 1


@dataclass(frozen=True)
class ParamSpec:
    """One parameter of a node.

    Attributes:
        name: the parameter's name.
        default: its value when not set (bool, int, float, str or a tuple of str).
        description: what it means, with its unit.
        minimum, maximum: inclusive range of a number (None: unbounded that way).
        choices: the allowed strings (or, for a list, the allowed items); empty: any.
        live: applied while the node runs (``ros2 param set``); otherwise read once, at
            start-up or, for a lifecycle node, at configure.
        at_start: read at start-up even by a lifecycle node (``autostart``).
    """

    name: str
    default: bool | int | float | str | tuple[str, ...]
    description: str
    minimum: float | None = None
    maximum: float | None = None
    choices: tuple[str, ...] = ()
    live: bool = False
    at_start: bool = False

    @property
    def kind(self) -> type:
        """The parameter's Python type: bool, int, float, str or tuple (of str)."""
        return type(self.default)

    def value(self, raw):
        """``raw`` as this parameter's type (an int for a float parameter becomes a float).

        Raises:
            ValueError: one line naming the parameter, what it takes and what it got.
        """
        problem = self.problem(raw)
        if problem:
            raise ValueError(problem)
        if self.kind is float:
            return float(raw)
        if self.kind is tuple:
            return tuple(raw)
        return raw

    def problem(self, raw) -> str:
        """Why ``raw`` is not a valid value of this parameter; "" if it is."""
        kind = self.kind
        number = isinstance(raw, (int, float)) and not isinstance(raw, bool)
        if kind is bool and not isinstance(raw, bool):
            return f"parameter {self.name} must be true or false, got {raw!r}"
        if kind is int and (not isinstance(raw, int) or isinstance(raw, bool)):
            return f"parameter {self.name} must be an integer, got {raw!r}"
        if kind is float and (not number or not math.isfinite(raw)):
            return f"parameter {self.name} must be a finite number, got {raw!r}"
        if kind is str and not isinstance(raw, str):
            return f"parameter {self.name} must be a string, got {raw!r}"
        if kind is tuple and (
            not isinstance(raw, (list, tuple)) or not all(isinstance(v, str) for v in raw)
        ):
            return f"parameter {self.name} must be a list of strings, got {raw!r}"
        if kind in (int, float) and not self.in_range(raw):
            return f"parameter {self.name} must be {self.range_text()}, got {raw!r}"
        items = raw if kind is tuple else [raw]
        bad = [v for v in items if self.choices and v not in self.choices]
        if bad:
            return (
                f"parameter {self.name} must be "
                f"{'made of' if kind is tuple else 'one of'} {', '.join(self.choices)}; "
                f"got {raw!r}"
            )
        return ""

    def in_range(self, value: float) -> bool:
        """True if ``value`` is within [minimum, maximum]."""
        low = -math.inf if self.minimum is None else self.minimum
        high = math.inf if self.maximum is None else self.maximum
        return low <= value <= high

    def range_text(self) -> str:
        """The range in words: "between 0.0 and 10.0", "at least 1"."""
        if self.minimum is not None and self.maximum is not None:
            return f"between {self.minimum} and {self.maximum}"
        if self.minimum is not None:
            return f"at least {self.minimum}"
        return f"at most {self.maximum}"


def spec(name: str, default, description: str, low=None, high=None, **kw) -> ParamSpec:
    """A :class:`ParamSpec` in one line (``low``/``high``: the inclusive range)."""
    return ParamSpec(name, default, description, low, high, **kw)


#: Every node reports on /diagnostics (docs/design.md section 9).
COMMON = (
    spec("diagnostics_period", 1.0, "s between /diagnostics messages", 0.1, 60.0, at_start=True),
)
#: The nodes that draw what they see or choose.
MARKERS = (
    spec("markers", False, "publish visualization markers on ~/markers (RViz, Foxglove)"),
    spec("marker_frame", "base_link", "frame of the markers: the robot's body frame"),
)
#: A lifecycle node's own.
MANAGED = (
    spec(
        "autostart",
        True,
        "configure and activate at start-up (false: wait for ros2 lifecycle or a launch "
        "file to drive the transitions)",
        at_start=True,
    ),
)
_LAYOUT = spec(
    "sensor_layout",
    "",
    "sensor layout YAML or arbitrator JSON; empty: the shipped 4ws-5 controller's",
)
#: The nodes that take the sensor streams ``scan`` and ``odom``.
_INPUT_QOS = spec(
    "input_qos",
    "sensor_data",
    "QoS of the scan and odom subscriptions: sensor_data (best effort, as drivers publish) "
    "or reliable (a lockstep graph, so that no first message is lost to a match still "
    "completing; docs/design.md section 9)",
    choices=("sensor_data", "reliable"),
)
_TWO_PI = 2.0 * math.pi

PARAMETERS: dict[str, tuple[ParamSpec, ...]] = {
    "laser_sensor": (
        _LAYOUT,
        spec("laser_x", 0.0, "scanner position on the robot, x forward (m)", -10.0, 10.0),
        spec("laser_y", 0.0, "scanner position on the robot, y left (m)", -10.0, 10.0),
        spec("laser_yaw", 0.0, "scanner yaw in the robot frame (rad)", -_TWO_PI, _TWO_PI),
        _INPUT_QOS,
        *MARKERS,
        *COMMON,
    ),
    "radar_sensor": (
        _LAYOUT,
        spec(
            "goal_type",
            "point",
            "goal message type: point (PointStamped) or pose (PoseStamped)",
            choices=("point", "pose"),
        ),
        _INPUT_QOS,
        *MARKERS,
        *COMMON,
    ),
    "arbitrator": (
        *MANAGED,
        spec(
            "arbitrator",
            "",
            "arbitrator file (JSON); empty: the shipped one for robot (4ws-5 if unset)",
        ),
        spec("repertoire", "", "repertoire file (JSON); empty: the shipped one for its robot"),
        spec(
            "robot",
            "",
            "the robot driven (a registered robot, e.g. 4ws-5 or hexapod): a controller for "
            "another is refused; empty: not checked",
        ),
        spec(
            "allow_mismatch",
            False,
            "run with a repertoire or sensor layout other than the arbitrator's",
        ),
        spec("sensor_layout", "", "the sensor nodes' layout (YAML); empty: the arbitrator's own"),
        spec("record_file", "", "append every choice here as JSON lines (m1, m2, x, y, primitive)"),
        spec(
            "adaptation",
            False,
            "correct the primitives' outcomes from odometry (odom) and choose by the "
            "corrected ones (docs/design.md section 24); false: as evolved, and forgets",
            live=True,
        ),
        spec(
            "adaptation_expected",
            "recorded",
            "what adaptation compares an observation with: recorded (the repertoire's "
            "outcomes, measured from rest) or settled (what each primitive does once its "
            "actuators hold its command, or a legged robot's whole execution after other "
            "primitives, from settled_outcomes); a change while adapting "
            "starts again from the prior",
            choices=("recorded", "settled"),
            live=True,
        ),
        spec(
            "settled_outcomes",
            "",
            "settled-outcomes file (JSON, evorbc-evolve settled) read for adaptation_expected "
            "settled; empty: the one beside the repertoire (NAME.settled.json)",
        ),
        _INPUT_QOS,
        *MARKERS,
        *COMMON,
    ),
    "primitive_executor": (
        *MANAGED,
        spec("robot", "4ws-5", "robot type (a registered robot, e.g. 4ws-5)"),
        spec(
            "wheel_radius",
            0.0,
            "wheel radius (m) for wheel velocities, applied live; 0: the robot's own",
            0.0,
            10.0,
            live=True,
        ),
        spec("period", 0.1, "command period (s)", 0.001, 10.0),
        spec("stale_timeout", 0.3, "stop when an input is older than this (s)", 0.001, 60.0),
        spec(
            "zero_before_first_primitive",
            False,
            "4WS: send zero commands every period until the first primitive arrives (false: "
            "send nothing, so another node may drive the robot)",
        ),
        spec(
            "watched_inputs",
            ("rangefinders", "goal_sectors"),
            "the sensor inputs whose silence stops the robot (evorbc/<input>)",
            choices=("rangefinders", "goal_sectors"),
        ),
        spec(
            "trajectory_rate",
            0.0,
            "legged robots: trajectory points per second; 0: the robot's physics rate",
            0.0,
            10000.0,
        ),
        spec(
            "twist_stamped",
            True,
            "differential drive: geometry_msgs/TwistStamped on cmd_vel (Jazzy's "
            "diff_drive_controller); false: Twist (TurtleBot3's base, older stacks)",
        ),
        spec(
            "lockstep",
            False,
            "a lockstep simulation: send a command only in answer to a primitive, never "
            "on the timer (the simulation takes each command for a cycle's)",
        ),
        *COMMON,
    ),
}

#: Topic-name parameters of earlier versions: node -> parameter -> the topic to remap.
REMOVED: dict[str, dict[str, str]] = {
    "laser_sensor": {"scan_topic": "scan", "output_topic": "evorbc/rangefinders"},
    "radar_sensor": {
        "odom_topic": "odom",
        "goal_topic": "goal",
        "output_topic": "evorbc/goal_sectors",
    },
    "arbitrator": {
        "rangefinder_topic": "evorbc/rangefinders",
        "goal_topic": "evorbc/goal_sectors",
        "primitive_topic": "evorbc/primitive",
        "mapping_topic": "evorbc/mapping",
    },
    "primitive_executor": {
        "primitive_topic": "evorbc/primitive",
        "input_topics": "evorbc/rangefinders and evorbc/goal_sectors (which stop the robot "
        "when silent: parameter watched_inputs)",
        "steering_topic": "steering_position_controller/commands",
        "wheel_topic": "wheel_velocity_controller/commands",
        "trajectory_topic": "joint_trajectory_controller/joint_trajectory",
        "cmd_vel_topic": "cmd_vel",
    },
}


def removed_problem(given: set[str], removed: dict[str, str]) -> str:
    """One line for the first removed parameter in ``given``; "" if none is there.

    ``removed``: a node's entry of :data:`REMOVED` (parameter -> the topic to remap).
    """
    for name, topic in removed.items():
        if name in given:
            first = topic.split(" ")[0]
            return (
                f"parameter {name} was removed: topics have fixed names now; remap instead: "
                f"--ros-args -r {first}:=<your topic>" + (f" ({topic})" if first != topic else "")
            )
    return ""
