"""Shared pieces of the evorbc ROS 2 nodes: QoS, vector messages, start-up and main().

Conventions (docs/design.md section 9): sensor streams from other stacks are subscribed with
``qos_profile_sensor_data``; everything evorbc publishes is reliable (a best-effort
subscriber still receives it); the goal is latched (transient local) so a node that starts
late still gets it.

Parameters are declared from each node's table (:mod:`evorbc_ros.nodes.parameters`). A
node that cannot start logs one line through its own logger (console, ``/rosout`` and the
log file) and exits with status 2.
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

#: Our own streams: reliable, with a deep history. A reliable writer keeps only its last
#: ``depth`` samples for a reader that has not acknowledged them, and a lockstep graph runs
#: hundreds of cycles a second: with 10, a recorder that stalled for a moment on a loaded
#: machine (a disk flush, a starved core) lost a state's /scan and /odom (one cycle in 819).
#: 1000 is the bag recorder's own depth: some kB per topic, no loss.
RELIABLE = QoSProfile(
    depth=1000, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST
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


def input_qos(name: str) -> QoSProfile:
    """The QoS of a sensor stream's subscription for the ``input_qos`` parameter's value.

    ``sensor_data`` takes what drivers publish (best effort). ``reliable`` is for a lockstep
    graph, whose publishers are reliable: a best-effort reader drops a message that reaches
    it before its side of the match completes, and a lockstep cycle lost so is never
    answered (docs/design.md section 9).
    """
    return RELIABLE if name == "reliable" else SENSOR_DATA


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


_stopping = False


def stop_on_first_signal() -> None:
    """Make SIGINT and SIGTERM stop the node once; later ones are ignored.

    The handler only notes the stop: the node's loop (:func:`spin_until_stopped`, the
    bridge's loops) sees it within its wait timeout and ends, and only then are the nodes
    destroyed and the context shut down. rclpy's own handlers are not installed
    (``SignalHandlerOptions.NO`` in :func:`init_ros`): they shut the context down from
    another thread at once, and a callback logging at that moment then fails to publish
    to ``/rosout`` and rcl prints an error; raising KeyboardInterrupt instead would land
    anywhere, in a numba compiler callback or in ``destroy_node``, and print a traceback.
    ``ros2 launch`` run from a script sends a second SIGINT while the nodes shut down: it
    is ignored.
    """

    def on_signal(signum, frame) -> None:
        global _stopping
        _stopping = True

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)


def stop_requested() -> bool:
    """True once SIGINT or SIGTERM arrived (see :func:`stop_on_first_signal`)."""
    return _stopping


def running() -> bool:
    """True while no stop was requested and the ROS context is up."""
    return not _stopping and rclpy.ok()


#: Longest wait (s) of a node's loop: how late a node may notice a stop request.
STOP_POLL = 0.1


def spin_until_stopped(node: Node) -> None:
    """Run ``node``'s callbacks until a signal asks the process to stop.

    Waits are bounded by :data:`STOP_POLL`, because no rclpy signal handler wakes them.
    """
    executor = Executor(context=node.context)
    executor.add_node(node)
    try:
        while running():
            executor.spin_once(timeout_sec=STOP_POLL)
    finally:
        executor.remove_node(node)
        executor.shutdown()


def quiet_teardown() -> None:
    """Ignore SIGINT and SIGTERM from now on: the process is finishing anyway.

    Python restores the default action of every signal it handled as it exits, and a late
    SIGINT would then kill the process (status -2) after a clean stop.
    """
    from rclpy.signals import uninstall_signal_handlers

    uninstall_signal_handlers()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    # CPython marks the process as ended by Ctrl-C when a KeyboardInterrupt leaves code run
    # by exec() of a string (numba and dataclasses compile that way), even once caught,
    # and then kills itself with SIGINT as it exits (status -2 after a clean stop). Each
    # such exec() clears the mark first; this one clears it for good.
    exec("None")


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


class Executor(rclpy.executors.SingleThreadedExecutor):
    """rclpy's single-threaded executor, safe to make if the context is already shut down.

    Its ``__init__`` then fails, and rclpy's ``__del__`` reads an attribute that was never
    set and prints a traceback; the class attribute gives it one.
    """

    _sigint_gc = None


def init_ros(argv: Sequence[str] | None) -> int | None:
    """``rclpy.init`` after :func:`stop_on_first_signal`, without rclpy's signal handlers.

    Returns:
        None to go on; otherwise the exit status: 2 after one line on bad arguments, 0 if
        a signal came first.
    """
    from rclpy.signals import SignalHandlerOptions

    stop_on_first_signal()
    try:
        rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as e:  # rcl reports bad --ros-args as a generic RCLError
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        print(f"error: cannot start: {first}", file=sys.stderr)
        return 2
    if stop_requested():
        quiet_teardown()
        rclpy.try_shutdown()
        return 0
    return None


def run_node(make: Callable[[], Node], argv: Sequence[str] | None = None) -> int:
    """Init / construct / spin / destroy / try_shutdown (the ROS 2 demos' main).

    Returns 0 after Ctrl-C or SIGTERM, 2 if the node cannot start (the node has logged
    why; see :func:`logged_startup`).
    """
    status = init_ros(argv)
    if status is not None:
        return status
    node = None
    try:
        node = make()
        spin_until_stopped(node)
        finish = getattr(node, "finish", None)  # a lifecycle node stops the robot
        if finish is not None and rclpy.ok(context=node.context):
            finish()
    except StartupError as e:
        if not e.logged:
            print(f"error: {e}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    except Exception:
        if not stop_requested():
            raise
    finally:
        quiet_teardown()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


def robot_named(name: str):
    """The registered robot (:mod:`evorbc_ros.robots.registry`) a ``robot`` parameter names.

    Raises:
        StartupError: one line listing the known robots.
    """
    from evorbc_ros.robots import registry

    if not registry.known(name):
        raise StartupError(
            f"parameter robot must be one of {', '.join(registry.names())}, got {name!r}"
        )
    return registry.lookup(name)


def load_sensor_layout(path: str):
    """The sensor layout from a layout YAML, an arbitrator file, or the default robot's.

    The default robot's layout (``path`` empty) is that of its shipped controller, which the
    arbitrator node runs when given none, so nodes started without parameters fit together
    whatever layout that controller has; for a default robot shipping none, its sensors file.

    Raises:
        StartupError: naming the file and the problem.
    """
    from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
    from evorbc_ros.config import ConfigError
    from evorbc_ros.defaults import default_arbitrator, ships_controller
    from evorbc_ros.robots.registry import DEFAULT_ROBOT, lookup
    from evorbc_ros.sensors import SensorLayout

    try:
        if not path and ships_controller(DEFAULT_ROBOT):
            return ArbitratorFile.load(default_arbitrator(DEFAULT_ROBOT)).sensors
        if not path:
            return SensorLayout.load(lookup(DEFAULT_ROBOT).sensors_file())
        if path.endswith(".json"):
            return ArbitratorFile.load(path).sensors
        return SensorLayout.load(path)
    except (ConfigError, ArbitratorError) as e:
        raise StartupError(f"parameter sensor_layout: {e}") from None
