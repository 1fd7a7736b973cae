"""``arbitrator``: sensor readings -> network -> mapping -> primitive (a lifecycle node).

Subscribes ``evorbc/rangefinders`` and ``evorbc/goal_sectors`` (Float64MultiArray); once
both have a new message it publishes the chosen primitive's genes on ``evorbc/primitive``
(Float64MultiArray, labelled with the parameter names) and, for EvoRBC, the diagnostic
``evorbc/mapping`` = ``[m1, m2, x, y, primitive index]``, also appended to ``record_file``
(JSON lines) if set. A recurrent network's state starts at 0 at every activation; the
service ``~/reset`` (std_srvs/Empty) sets it back to 0, for a new goal or a new run.

Configure loads and checks the files (by default the arbitrator and repertoire shipped for
``robot``, so ``ros2 run evorbc_ros arbitrator`` needs no arguments): a bad file, a
repertoire or sensor mismatch, or a controller for another robot than ``robot`` fails it in
one line. Activate starts choosing, at once if a full set of readings came meanwhile;
deactivate publishes an empty primitive, which stops the robot. Health on
``/diagnostics``; with ``markers`` the mapping's target and the chosen primitive's
expected displacement on ``~/markers`` (:mod:`evorbc_ros.nodes.managed`).

With ``adaptation`` (off by default; applied live, and false forgets what was learned)
the node also subscribes ``odom`` (nav_msgs/Odometry, sensor-data QoS: the radar node's
odometry), chooses once a new pose has come with the readings, and runs the primitive
whose outcome, corrected from what the primitives did, is nearest what the network's
choice was recorded to do (docs/design.md section 24). ``~/reset_adaptation``
(std_srvs/Empty) forgets the observations. Its state is in the health report, and the
chosen primitive's corrected displacement in the markers.

``adaptation_expected`` (applied live) is what an observation is compared with:
``recorded``, the repertoire's outcomes (the default), or ``settled``, what each primitive
does once its actuators hold its command, read from the file ``settled_outcomes`` (empty:
``NAME.settled.json`` beside the repertoire; ``evorbc-evolve settled`` writes it). That file
is checked when ``settled`` is asked for: at configure, a missing, bad or mismatched file
fails the configure in one line; set live, it refuses the change with that line, and the
node goes on as it was. A change while adapting starts again from the prior.
"""

from __future__ import annotations

import json
import math
import os
import sys

import numpy as np
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import SetParametersResult
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Empty
from visualization_msgs.msg import MarkerArray

from evorbc_ros.adaptation.settled import SettledError
from evorbc_ros.arbitration import DEACTIVATED, Controller, InputGroups
from evorbc_ros.arbitrator import ArbitratorError
from evorbc_ros.defaults import default_arbitrator, no_shipped_controller, ships_controller
from evorbc_ros.goal import yaw_from_quaternion
from evorbc_ros.health import ERROR, WARN, Health, Meter, report_input, report_skipped
from evorbc_ros.laser import InputError
from evorbc_ros.marker_geometry import primitive_arrows
from evorbc_ros.nodes.common import (
    DIAGNOSTICS,
    StartupError,
    input_qos,
    load_sensor_layout,
    now_seconds,
    robot_named,
    run_node,
    vector_message,
    vector_values,
)
from evorbc_ros.nodes.managed import ManagedNode
from evorbc_ros.nodes.markers import Markers, arrow, sphere
from evorbc_ros.repertoire import RepertoireError

#: The input groups, in the order of the network's inputs.
INPUTS = ("evorbc/rangefinders", "evorbc/goal_sectors")
#: s after which an input counts as old in the health report (three control periods).
STALE = 0.3


class ArbitratorNode(ManagedNode):
    """Chooses a primitive whenever a full set of new readings has arrived."""

    NAME = "arbitrator"

    def __init__(self, **kwargs) -> None:
        self.controller: Controller | None = None
        self.groups: InputGroups | None = None
        self.pub = self.map_pub = None
        self.record = None
        self.markers: Markers | None = None
        self.meters = {t: Meter() for t in INPUTS}
        self.skipped, self.choices, self.halts, self.failures = Meter(), Meter(), Meter(), Meter()
        self.last_choice: list[float] = []
        self.odom_sub = None  # made when adaptation starts
        self.pose_fresh = False  # a pose came since the last choice (adaptation only)
        self.poses = Meter()
        self.expected = "recorded"  # adaptation_expected
        self.settled_file = ""  # settled_outcomes, as configured
        self.settled: np.ndarray | None = None  # (n, 3) read once settled is asked for
        super().__init__(**kwargs)
        # Checked before rclpy takes the value, so a bad file refuses the change itself.
        self.add_on_set_parameters_callback(self.check_expected)
        self.reset_service = self.create_service(Empty, "~/reset", self.on_reset)
        self.reset_adaptation_service = self.create_service(
            Empty, "~/reset_adaptation", self.on_reset_adaptation
        )

    # -- lifecycle ----------------------------------------------------------------------

    def configure(self, params: dict) -> None:
        """Load the controller and the record file; make the publishers and subscriptions."""
        self.controller = load_controller(
            params["arbitrator"],
            params["repertoire"],
            params["robot"],
            params["allow_mismatch"],
            params["sensor_layout"],
        )
        self.record = open_record(params["record_file"])
        for w in self.controller.warnings:
            self.get_logger().warning(w)
        spec = self.controller.spec
        self.diagnostics.hardware_id = spec.robot
        layout = spec.sensors
        n_rf = len(layout.rangefinders.angles) if layout.rangefinders else 0
        sizes = dict(zip(INPUTS, (n_rf, layout.n_inputs - n_rf), strict=True))
        self.groups = InputGroups({k: v for k, v in sizes.items() if v > 0})
        self.pub = self.lifecycle_publisher(Float64MultiArray, "evorbc/primitive")
        self.map_pub = self.lifecycle_publisher(Float64MultiArray, "evorbc/mapping", DIAGNOSTICS)
        if params["markers"]:
            pub = self.lifecycle_publisher(MarkerArray, "~/markers")
            self.markers = Markers(self, params["marker_frame"], pub)
        for t in self.groups.sizes:
            self.subscription(Float64MultiArray, t, lambda msg, t=t: self.on_input(t, msg))
        self.expected, self.settled_file = params["adaptation_expected"], params["settled_outcomes"]
        self.odom_qos = input_qos(params["input_qos"])
        if self.expected == "settled" and self.controller.repertoire is not None:
            self.settled = self.read_settled()  # a bad file fails the configure
        if params["adaptation"]:
            self.start_adaptation()
        self.get_logger().info(
            f"{spec.kind.name} controller for {spec.robot} from {self.controller.arbitrator_path}"
            + (
                f" over {self.controller.repertoire_path} "
                f"({len(self.controller.repertoire)} primitives)"
                if self.controller.repertoire is not None
                else ""
            )
        )

    def activate(self) -> None:
        """Start from a fresh network state; choose at once if a full set is waiting.

        An episode starts with the node's activation (the bridge sends the first state once
        the graph is up), so a recurrent network starts from 0 there, as offline.
        """
        self.controller.reset()
        if self.controller.recurrent:
            self.get_logger().info("recurrent network: its state starts at 0")
        if self.ready():
            self.choose()

    def deactivate(self) -> None:
        """An empty primitive: the executor stops the robot at once.

        Labelled ``deactivated`` (the label of a choice is its genes' names), so that a
        recording tells it from a cycle's "no primitive".
        """
        self.pub.publish(vector_message([], [DEACTIVATED]))
        self.get_logger().info("deactivated: sent no primitive (the robot stops)")

    def release(self) -> None:
        """Close the record file; drop the subscriptions, publishers and controller."""
        self.release_made()
        self.pub = self.map_pub = self.markers = self.odom_sub = None
        self.settled = None
        if self.record is not None:
            self.record.close()
            self.record = None
        self.controller = None

    def read_settled(self) -> np.ndarray:
        """``(n, 3)`` the settled outcomes of ``settled_outcomes`` (or beside the repertoire).

        Raises:
            StartupError: one line naming the parameter and the file's problem.
        """
        try:
            return self.controller.settled_outcomes(self.settled_file)
        except SettledError as e:
            raise StartupError(f"parameter adaptation_expected is settled, but {e}") from None

    def start_adaptation(self) -> None:
        """Adapt from the prior, against ``adaptation_expected``; subscribe odometry (once).

        Raises:
            StartupError: a standard-NEAT controller (no primitives to correct).
        """
        expected = self.settled if self.expected == "settled" else None
        try:
            self.controller.enable_adaptation(expected=expected)
        except ValueError as e:
            raise StartupError(f"parameter adaptation: {e}") from None
        if self.odom_sub is None:
            self.odom_sub = self.subscription(Odometry, "odom", self.on_odom, self.odom_qos)
        self.pose_fresh = False
        self.get_logger().info(
            f"adaptation on: correcting outcomes from odometry (expected: {self.expected})"
        )

    def check_expected(self, params: list) -> SetParametersResult:
        """Refuse ``adaptation_expected: settled`` when its file cannot be used (configured).

        Unconfigured, any valid value is taken: configure reads the file.
        """
        for p in params:
            if p.name != "adaptation_expected" or p.value != "settled":
                continue
            if self.controller is None or self.controller.repertoire is None:
                continue  # configure reads it; a standard controller does not adapt
            if self.settled is None:
                try:
                    self.settled = self.read_settled()
                except StartupError as e:
                    return SetParametersResult(successful=False, reason=str(e))
        return SetParametersResult(successful=True)

    def apply_live(self, name: str, value) -> None:
        """``adaptation``: true starts from the prior; false stops and forgets.

        ``adaptation_expected``: while adapting, starts again from the prior against the
        new expected outcomes (the observations were compared with the others).
        """
        if self.controller is None:
            return  # before configure: configure reads it
        if name == "adaptation_expected":
            if value == self.expected:
                return  # set to what it is (ros2 param load): keep what was learned
            self.expected = value
            if self.controller.adaptation is not None:
                self.start_adaptation()
            return
        if name != "adaptation":
            return
        if value and self.controller.adaptation is None:
            try:
                self.start_adaptation()
            except StartupError as e:
                self.get_logger().error(str(e))
        elif not value and self.controller.adaptation is not None:
            self.controller.disable_adaptation()
            self.get_logger().info("adaptation off: the recorded outcomes again")

    def ready(self) -> bool:
        """Every input group is new, and so is the pose when adapting."""
        return all(self.groups.fresh.values()) and (
            self.controller.adaptation is None or self.pose_fresh
        )

    # -- callbacks ----------------------------------------------------------------------

    def on_reset_adaptation(
        self, request: Empty.Request, response: Empty.Response
    ) -> Empty.Response:
        """``~/reset_adaptation``: forget every observation (the recorded outcomes again)."""
        if self.controller is None or self.controller.adaptation is None:
            self.get_logger().info("reset_adaptation: adaptation is off, nothing to forget")
            return response
        self.controller.reset_adaptation()
        self.get_logger().info("reset_adaptation: observations forgotten")
        return response

    def on_odom(self, msg: Odometry) -> None:
        """Hand the pose to the controller; choose if the readings were waiting for it."""
        if self.controller is None or self.controller.adaptation is None:
            return
        self.poses.tick(now_seconds(self))
        pose = msg.pose.pose
        q = pose.orientation
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        yaw = yaw_from_quaternion(q.x, q.y, q.z, q.w)
        self.controller.put_pose(stamp, pose.position.x, pose.position.y, yaw)
        self.pose_fresh = True
        if self.active and self.ready():
            self.choose()

    def on_reset(self, request: Empty.Request, response: Empty.Response) -> Empty.Response:
        """``~/reset``: a recurrent network's state back to 0 (as at an episode's start).

        Readings already received for the current cycle are kept: the next choice uses
        them with the fresh state. A feed-forward network has no state; the call is logged
        and changes nothing. Before configure there is nothing to reset.
        """
        if self.controller is None:
            self.get_logger().info("reset: not configured, nothing to reset")
            return response
        self.controller.reset()
        what = "state set to 0" if self.controller.recurrent else "feed-forward, no state"
        self.get_logger().info(f"reset: {what}")
        return response

    def on_input(self, topic: str, msg: Float64MultiArray) -> None:
        """Store one input group; choose once all are new (and the node is active)."""
        now = now_seconds(self)
        try:
            values = vector_values(msg, self.groups.sizes[topic], topic)
        except InputError as e:
            self.skipped.tick(now)
            self.get_logger().warning(f"skipped a message: {e}", throttle_duration_sec=2.0)
            return
        self.meters[topic].tick(now)
        if self.groups.put(topic, values) and self.active and self.ready():
            self.choose()

    def choose(self) -> None:
        """One choice from the held inputs: publish it, record it, draw it.

        A network whose outputs are not finite chooses no primitive: an empty message on
        the primitive topic stops the robot at once (the executor's rule), and the cycle
        is logged. So is any other failure of the choice, which must never end the node.
        """
        now = now_seconds(self)
        inputs = self.groups.take()
        self.pose_fresh = False
        try:
            genes, diagnostics = self.controller.step(inputs)
        except Exception as e:  # a controller bug must stop the robot, not the node
            genes, diagnostics = np.empty(0), []
            self.failures.tick(now)
            self.get_logger().error(
                f"choosing a primitive failed ({type(e).__name__}: {e}); the robot stops",
                throttle_duration_sec=2.0,
            )
        else:
            reason = self.controller.no_primitive_reason(inputs, genes, diagnostics)
            if reason:
                self.halts.tick(now)
                self.get_logger().warning(reason, throttle_duration_sec=2.0)
        self.choices.tick(now)
        self.last_choice = diagnostics or list(map(float, genes))
        names = self.controller.parameter_names if len(genes) else []
        self.pub.publish(vector_message(genes, names))
        if diagnostics:
            self.map_pub.publish(vector_message(diagnostics, ["m1", "m2", "x", "y", "primitive"]))
        if self.record is not None:
            # JSON has no NaN or infinity: a value outside float range is written as null.
            row = [v if math.isfinite(v) else None for v in self.last_choice]
            self.record.write(json.dumps(row) + "\n")
        if self.markers is not None and diagnostics:
            self.publish_markers(diagnostics)

    def publish_markers(self, row: list[float]) -> None:
        """The mapping's target point, and the chosen primitive's expected motion."""
        _, _, x, y, index = row
        if not all(math.isfinite(v) for v in row):
            return
        rep = self.controller.repertoire
        k = int(index)
        move, turn = primitive_arrows(tuple(rep.behaviour[k]), float(rep.heading[k]), 0.1)
        out = [
            sphere("mapping_target", (x, y), (1.0, 0.2, 0.8, 0.9), 0.05),
            arrow("primitive", move, (0.2, 0.9, 0.2, 0.9), 0.02),
            arrow("primitive", turn, (0.2, 0.9, 0.2, 0.9), 0.01, idx=1),
        ]
        if self.controller.adaptation is not None:  # what it is now expected to do
            dx, dy, dh = self.controller.adaptation.model.corrected[k]
            move, turn = primitive_arrows((float(dx), float(dy)), float(dh), 0.1)
            out.append(arrow("corrected", move, (1.0, 0.6, 0.1, 0.9), 0.02))
            out.append(arrow("corrected", turn, (1.0, 0.6, 0.1, 0.9), 0.01, idx=1))
        self.markers.publish(out)

    def report(self, h: Health, now: float) -> None:
        """Inputs, choices per second, the chosen primitive, skipped and failed choices."""
        for topic in self.groups.sizes:
            report_input(h, topic, self.meters[topic], now, STALE)
        report_skipped(h, "input", self.skipped, now)
        new_halts, new_failures = self.halts.new_since_report(), self.failures.new_since_report()
        self.halts.rate(now)
        self.failures.rate(now)
        h.add("choices per second", self.choices.rate(now))
        h.add("last choice", self.last_choice)
        h.add("no primitive", self.halts.count)
        h.add("failed choices", self.failures.count)
        if self.controller is not None and self.controller.adaptation is not None:
            report_input(h, "odometry", self.poses, now, STALE)
            h.add("adaptation: expected", self.expected)
            for key, value in self.controller.adaptation_state().items():
                h.add(f"adaptation: {key}", value)
        if new_halts:
            h.worse(WARN, f"{new_halts} cycle(s) without a primitive (the robot stopped)")
        if new_failures:
            h.worse(ERROR, f"{new_failures} choice(s) failed (the robot stopped)")

    def destroy_node(self) -> None:
        """Close the record file, then the node."""
        self.release()
        super().destroy_node()


def open_record(path: str):
    """``path`` opened for appending lines (None for ""), refusing what is not a file.

    Raises:
        StartupError: naming the parameter.
    """
    if not path:
        return None
    # An existing non-regular file (a FIFO) would block open() until a reader comes.
    if os.path.exists(path) and not os.path.isfile(path):
        raise StartupError(f"parameter record_file: {path} is not a regular file")
    try:
        return open(path, "a", buffering=1)
    except OSError as e:
        raise StartupError(f"parameter record_file: cannot open {path} ({e.strerror})") from None


def load_controller(
    arbitrator: str, repertoire: str, robot: str, allow: bool, layout_path: str
) -> Controller:
    """The controller the parameters name, checked against ``robot`` and the sensor layout.

    An empty ``arbitrator`` means the one shipped for ``robot`` (4ws-5 if ``robot`` is
    empty). A controller for another robot than ``robot`` could never drive it: its
    primitives have other parameters (docs/design.md section 9), so it is refused here, not
    discovered later as a robot that never moves.

    Raises:
        StartupError: one line naming the parameter or file and the problem.
    """
    if robot:
        robot_named(robot)
    if not arbitrator and robot:
        if not ships_controller(robot):
            raise StartupError(
                f"parameter robot: {no_shipped_controller(robot)}; then set "
                "arbitrator:=a.json and repertoire:=r.json"
            )
        arbitrator = str(default_arbitrator(robot))
    try:
        controller = Controller(arbitrator, repertoire, allow)
        if layout_path:
            controller.warnings += controller.spec.check_sensors(
                load_sensor_layout(layout_path), layout_path, allow
            )
    except (ArbitratorError, RepertoireError) as e:
        raise StartupError(str(e)) from None
    if robot and controller.spec.robot != robot:
        raise StartupError(
            f"{controller.arbitrator_path}: is a controller for robot {controller.spec.robot}, "
            f"but parameter robot is {robot}"
        )
    return controller


def main(argv=None) -> int:
    """Run the node."""
    return run_node(ArbitratorNode, argv)


if __name__ == "__main__":
    sys.exit(main())
