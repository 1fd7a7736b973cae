"""``arbitrator``: sensor readings -> network -> mapping -> primitive.

Subscribes ``evorbc/rangefinders`` and ``evorbc/goal_sectors`` (Float64MultiArray); once
both have a new message it publishes the chosen primitive's genes on ``evorbc/primitive``
(Float64MultiArray, labelled with the parameter names) and, for EvoRBC, the diagnostic
``evorbc/mapping`` = ``[m1, m2, x, y, primitive index]``, also appended to ``record_file``
(JSON lines) if set. A recurrent network's state starts at 0 with the node; the service
``~/reset`` (std_srvs/Empty) sets it back to 0, for a new goal or a new run. By default it
runs the arbitrator and repertoire shipped with the package, so ``ros2 run evorbc_ros
arbitrator`` needs no arguments. Bad files, a repertoire/sensor mismatch, or a controller
for another robot than the ``robot`` parameter stop it at start-up with one line.
"""

from __future__ import annotations

import json
import math
import os
import sys

import numpy as np
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Empty

from evorbc_ros.arbitration import Controller, InputGroups
from evorbc_ros.arbitrator import ArbitratorError
from evorbc_ros.defaults import default_arbitrator, no_shipped_controller, ships_controller
from evorbc_ros.laser import InputError
from evorbc_ros.nodes.common import (
    DIAGNOSTICS,
    RELIABLE,
    StartupError,
    declare,
    load_sensor_layout,
    logged_startup,
    robot_named,
    run_node,
    vector_message,
    vector_values,
)
from evorbc_ros.repertoire import RepertoireError


class ArbitratorNode(Node):
    """Chooses a primitive whenever a full set of new readings has arrived."""

    def __init__(self, **kwargs) -> None:
        super().__init__("arbitrator", **kwargs)
        with logged_startup(self):
            arbitrator = declare(
                self,
                "arbitrator",
                "",
                "arbitrator file (JSON); empty: the shipped one for robot (4ws-5 if unset)",
            )
            repertoire = declare(
                self,
                "repertoire",
                "",
                "repertoire file (JSON); empty: the shipped one for its robot",
            )
            robot = declare(
                self,
                "robot",
                "",
                "the robot driven (a registered robot, e.g. 4ws-5 or hexapod): a controller "
                "for another is refused; empty: not checked",
            )
            allow = declare(
                self,
                "allow_mismatch",
                False,
                "run with a repertoire or sensor layout other than the arbitrator's",
            )
            layout_path = declare(
                self,
                "sensor_layout",
                "",
                "the sensor nodes' layout (YAML); empty: the arbitrator's own",
            )
            self.controller = load_controller(arbitrator, repertoire, robot, allow, layout_path)
            rf_topic = declare(
                self,
                "rangefinder_topic",
                "evorbc/rangefinders",
                "rangefinder readings (Float64MultiArray)",
            )
            goal_topic = declare(
                self, "goal_topic", "evorbc/goal_sectors", "goal readings (Float64MultiArray)"
            )
            out_topic = declare(
                self,
                "primitive_topic",
                "evorbc/primitive",
                "chosen primitive's genes (Float64MultiArray)",
            )
            map_topic = declare(
                self,
                "mapping_topic",
                "evorbc/mapping",
                "diagnostics [m1, m2, x, y, primitive] (Float64MultiArray)",
            )
            record = declare(
                self,
                "record_file",
                "",
                "append every choice here as JSON lines (m1, m2, x, y, primitive)",
            )
            # An existing non-regular file (a FIFO) would block open() until a reader comes.
            if record and os.path.exists(record) and not os.path.isfile(record):
                raise StartupError(f"parameter record_file: {record} is not a regular file")
            try:
                self.record = open(record, "a", buffering=1) if record else None  # noqa: SIM115
            except OSError as e:
                raise StartupError(
                    f"parameter record_file: cannot open {record} ({e.strerror})"
                ) from None
        for w in self.controller.warnings:
            self.get_logger().warning(w)
        # The node starts with its episode (the bridge sends the first state once the graph
        # is connected, in lockstep and real time), so a recurrent network starts from 0
        # there, as offline; a restarted node starts from 0 again, mid-episode.
        self.controller.reset()
        if self.controller.recurrent:
            self.get_logger().info("recurrent network: its state starts at 0")
        self.reset_service = self.create_service(Empty, "~/reset", self.on_reset)
        spec = self.controller.spec
        layout = spec.sensors
        n_rf = len(layout.rangefinders.angles) if layout.rangefinders else 0
        sizes = {rf_topic: n_rf, goal_topic: layout.n_inputs - n_rf}
        self.groups = InputGroups({k: v for k, v in sizes.items() if v > 0})
        self.pub = self.create_publisher(Float64MultiArray, out_topic, RELIABLE)
        self.map_pub = self.create_publisher(Float64MultiArray, map_topic, DIAGNOSTICS)
        self.subs = [
            self.create_subscription(
                Float64MultiArray, topic, lambda msg, t=topic: self.on_input(t, msg), RELIABLE
            )
            for topic in self.groups.sizes
        ]
        self.get_logger().info(
            f"{spec.kind} controller for {spec.robot} from {self.controller.arbitrator_path}"
            + (
                f" over {self.controller.repertoire_path} "
                f"({len(self.controller.repertoire)} primitives)"
                if self.controller.repertoire is not None
                else ""
            )
        )

    def on_reset(self, request: Empty.Request, response: Empty.Response) -> Empty.Response:
        """``~/reset``: a recurrent network's state back to 0 (as at an episode's start).

        Readings already received for the current cycle are kept: the next choice uses
        them with the fresh state. A feed-forward network has no state; the call is logged
        and changes nothing.
        """
        self.controller.reset()
        what = "state set to 0" if self.controller.recurrent else "feed-forward, no state"
        self.get_logger().info(f"reset: {what}")
        return response

    def on_input(self, topic: str, msg: Float64MultiArray) -> None:
        """Store one input group; choose once all are new.

        A network whose outputs are not finite chooses no primitive: an empty message on
        the primitive topic stops the robot at once (the executor's rule), and the cycle
        is logged. So is any other failure of the choice, which must never end the node.
        """
        try:
            values = vector_values(msg, self.groups.sizes[topic], topic)
        except InputError as e:
            self.get_logger().warning(f"skipped a message: {e}", throttle_duration_sec=2.0)
            return
        if not self.groups.put(topic, values):
            return
        inputs = self.groups.take()
        try:
            genes, diagnostics = self.controller.step(inputs)
        except Exception as e:  # a controller bug must stop the robot, not the node
            genes, diagnostics = np.empty(0), []
            self.get_logger().error(
                f"choosing a primitive failed ({type(e).__name__}: {e}); the robot stops",
                throttle_duration_sec=2.0,
            )
        else:
            reason = self.controller.no_primitive_reason(inputs, genes, diagnostics)
            if reason:
                self.get_logger().warning(reason, throttle_duration_sec=2.0)
        names = self.controller.parameter_names if len(genes) else []
        self.pub.publish(vector_message(genes, names))
        if diagnostics:
            self.map_pub.publish(vector_message(diagnostics, ["m1", "m2", "x", "y", "primitive"]))
        if self.record is not None:
            row = diagnostics or list(map(float, genes))
            # JSON has no NaN or infinity: a value outside float range is written as null.
            row = [v if math.isfinite(v) else None for v in row]
            self.record.write(json.dumps(row) + "\n")

    def destroy_node(self) -> None:
        """Close the record file, then the node."""
        if self.record is not None:
            self.record.close()
            self.record = None
        super().destroy_node()


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
