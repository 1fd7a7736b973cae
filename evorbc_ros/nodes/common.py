"""Shared pieces of the evorbc ROS 2 nodes: QoS, vector messages, start-up and main().

Conventions (DESIGN.md section 9): sensor streams from other stacks are subscribed with
``qos_profile_sensor_data``; everything evorbc publishes is reliable (a best-effort
subscriber still receives it); the goal is latched (transient local) so a node that starts
late still gets it.

Parameters are read once, at start-up, and declared read-only, so ``ros2 param set`` says
so instead of claiming a success that changes nothing; the few that a node applies live
say so in their description and are validated when set. A node that cannot start logs one
line through its own logger (console, ``/rosout`` and the log file) and exits with status 2.
"""

from __future__ import annotations

import contextlib
import signal
import sys
from collections.abc import Callable, Iterator, Sequence

import numpy as np
import rclpy
from rclpy.node import Node
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
)
from std_msgs.msg import Float64MultiArray, MultiArrayDimension

#: Our own streams: reliable, keep the last 10 (no loss in lockstep on one machine).
RELIABLE = QoSProfile(
    depth=10, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST
)
#: Diagnostics that tools record: a deep history, so a listener that falls behind for a
#: moment (a plotting tool, a test) does not lose samples.
DIAGNOSTICS = QoSProfile(
    depth=200, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST
)
#: Latched topics (the goal): late joiners get the last message.
LATCHED = QoSProfile(
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    history=HistoryPolicy.KEEP_LAST,
)
SENSOR_DATA = qos_profile_sensor_data


def _robot_names() -> tuple[str, ...]:
    from evorbc_ros.robots.four_ws import ROBOT_TYPES
    from evorbc_ros.robots.hexapod import HEXAPOD

    return (*ROBOT_TYPES, HEXAPOD)


#: Every robot type the nodes drive: the 4WS types (2ws-2, 2ws-3, 4ws-3, 4ws-5), hexapod.
ROBOTS = _robot_names()


class StartupError(Exception):
    """A node cannot start (bad parameter or file); the message says which and why."""

    #: Set once the node has logged the error through its logger.
    logged = False


@contextlib.contextmanager
def logged_startup(node: Node) -> Iterator[None]:
    """Log a :class:`StartupError` raised inside through ``node``'s logger, then re-raise.

    The node exists by then, so the line reaches ``/rosout`` and the ROS log file as well
    as the console, where ``ros2 launch`` users and log collectors look for it.
    """
    try:
        yield
    except StartupError as e:
        node.get_logger().fatal(f"cannot start: {e}")
        e.logged = True
        raise


def stop_on_first_signal() -> None:
    """SIGINT or SIGTERM stops the process once (KeyboardInterrupt); later ones are ignored.

    Call before ``rclpy.init``: rclpy's own handler (which wakes the executor and shuts
    the context down) then chains to this one. ``ros2 launch`` run from a script sends a
    second SIGINT while the nodes shut down; without this, that one raises inside
    ``destroy_node`` and prints a traceback.
    """
    stopping = False

    def on_signal(signum, frame) -> None:
        nonlocal stopping
        if not stopping:
            stopping = True
            raise KeyboardInterrupt

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)


def quiet_teardown() -> None:
    """Stop rclpy's signal handling before tearing down: no signal thread races the teardown.

    rclpy's handler thread shuts contexts down and triggers the executors' guard
    conditions on every signal; a second signal while the node and executor are being
    destroyed would touch objects being freed.
    """
    from rclpy.signals import uninstall_signal_handlers

    uninstall_signal_handlers()


def vector_message(values: Sequence[float], names: Sequence[str] = ()) -> Float64MultiArray:
    """A Float64MultiArray of ``values``; ``names`` go into the dimension label (comma list)."""
    msg = Float64MultiArray()
    msg.layout.dim = [
        MultiArrayDimension(label=",".join(names), size=len(values), stride=len(values))
    ]
    msg.data = [float(v) for v in values]
    return msg


def vector_values(msg: Float64MultiArray, expected: int, topic: str) -> np.ndarray:
    """The values of a vector message, checked for length and finiteness.

    Raises:
        evorbc_ros.laser.InputError: naming the topic and the problem.
    """
    from evorbc_ros.laser import InputError

    values = np.asarray(msg.data, dtype=np.float64)
    if values.shape != (expected,):
        raise InputError(f"{topic}: expected {expected} values, got {values.size}")
    if not np.all(np.isfinite(values)):
        raise InputError(f"{topic}: values must be finite, got {values.tolist()}")
    return values


def now_seconds(node: Node) -> float:
    """The node's clock (simulated when ``use_sim_time`` is set) in seconds."""
    return node.get_clock().now().nanoseconds * 1e-9


def init_ros(argv: Sequence[str] | None) -> bool:
    """``rclpy.init`` with :func:`stop_on_first_signal`; False (and one line) on bad args."""
    stop_on_first_signal()
    try:
        rclpy.init(args=argv)
    except Exception as e:  # rcl reports bad --ros-args as a generic RCLError
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        print(f"error: cannot start: {first}", file=sys.stderr)
        return False
    return True


def run_node(make: Callable[[], Node], argv: Sequence[str] | None = None) -> int:
    """Init / construct / spin / destroy / try_shutdown (the ROS 2 demos' main).

    Returns 0 after Ctrl-C or SIGTERM, 2 if the node cannot start (the node has logged
    why; see :func:`logged_startup`).
    """
    if not init_ros(argv):
        return 2
    node = None
    try:
        node = make()
        rclpy.spin(node)
    except StartupError as e:
        if not e.logged:
            print(f"error: {e}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        quiet_teardown()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


def declare(
    node: Node,
    name: str,
    default,
    description: str,
    any_type: bool = False,
    live: bool = False,
):
    """Declare a parameter with a description and return its value.

    Args:
        any_type: accept an override of any type (the caller checks it), so that
            ``-p rate:=100`` reaches a float parameter as an int instead of failing.
        live: the node applies changes while it runs (and validates them in its
            set-parameters callback); otherwise the parameter is read-only after start-up.

    Raises:
        StartupError: the override has another type than ``default``.
    """
    from rcl_interfaces.msg import ParameterDescriptor
    from rclpy.exceptions import InvalidParameterTypeException

    descriptor = ParameterDescriptor(
        description=description,
        dynamic_typing=any_type,
        read_only=not live,
    )
    try:
        return node.declare_parameter(name, default, descriptor).value
    except InvalidParameterTypeException:
        kind = {bool: "true or false", int: "an integer", float: "a number", str: "a string"}
        raise StartupError(
            f"parameter {name} must be {kind.get(type(default), type(default).__name__)}"
        ) from None


def load_sensor_layout(path: str):
    """The sensor layout from a layout YAML, an arbitrator file, or the shipped 4WS layout.

    Raises:
        StartupError: naming the file and the problem.
    """
    from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
    from evorbc_ros.config import ConfigError, config_dir
    from evorbc_ros.sensors import SensorLayout

    try:
        if not path:
            return SensorLayout.load(config_dir() / "sensors" / "4ws.yaml")
        if path.endswith(".json"):
            return ArbitratorFile.load(path).sensors
        return SensorLayout.load(path)
    except (ConfigError, ArbitratorError) as e:
        raise StartupError(f"parameter sensor_layout: {e}") from None


def sensor_layout_parameter(node: Node):
    """Declare a sensor node's ``sensor_layout`` parameter and load the layout it names.

    Raises:
        StartupError: naming the file and the problem.
    """
    path = declare(
        node,
        "sensor_layout",
        "",
        "sensor layout YAML or arbitrator JSON; empty: the shipped 4WS layout",
    )
    return load_sensor_layout(path)


def finite_parameter(
    node: Node,
    name: str,
    default: float,
    description: str,
    positive: bool = False,
    live: bool = False,
) -> float:
    """Declare a float parameter and check it is finite (and > 0 if ``positive``)."""
    value = declare(node, name, float(default), description, any_type=True, live=live)
    problem = finite_problem(name, value, positive)
    if problem:
        raise StartupError(problem)
    return float(value)


def finite_problem(name: str, value, positive: bool = False) -> str:
    """Why ``value`` is not a finite (positive) number for parameter ``name``; "" if it is."""
    import math

    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    if not number or not math.isfinite(value) or (positive and value <= 0):
        need = "a positive number" if positive else "a finite number"
        return f"parameter {name} must be {need}, got {value!r}"
    return ""
