"""``recorder``: record topics of the running graph into a rosbag2 bag (MCAP storage).

``python -P -m sim_bridge.recorder --ros-args -p bag:=DIR -p topics:=[/clock,scan,odom]``

Each topic is subscribed raw, so the bag holds the CDR bytes as they arrived
(:mod:`sim_bridge.rosbag_io`). A message is logged at the node's clock when its callback
runs: with ``use_sim_time`` (as in the simulated graph) that is the simulated time, so a
lockstep run's bag replays at its own pace, not at the wall clock's. Messages are written
in the order their callbacks run.

Parameters (read once, at start-up):

* ``bag``: the bag folder to create; an existing one is refused, never overwritten.
* ``topics``: the topics to record (relative names follow the node's namespace).
* ``types``: their message types (``sensor_msgs/msg/LaserScan``), in the order of
  ``topics``; empty, or an empty entry, takes the type from the graph once a publisher
  appears. A topic with a given type is subscribed at once, before any publisher exists;
  one whose type comes from the graph only once the recorder hears of its publisher, which
  may have published by then (give every type to record a run from its first message).
* ``latched``: the topics recorded with a transient-local subscription, because their
  publisher is latched (the graph's ``goal``, docs/design.md section 9) and a volatile
  subscription would miss a message published before it matched. A transient-local
  subscription never matches a volatile publisher, so the others stay volatile.

Once every topic's subscription has matched a publisher it logs so and publishes an empty
message on ``~/ready`` (std_msgs/Empty, latched), so that a lockstep bridge can hold its
first state until the recorder hears every node (see :meth:`RecorderNode.on_matched`).

SIGINT or SIGTERM stops it (docs/design.md section 9): it takes the messages already
delivered, closes the bag and exits with status 0. A bad parameter is one FATAL line and
status 2.
"""

from __future__ import annotations

import importlib
import re
import sys
import time

import rclpy
from rclpy.clock import Clock, ClockType
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Empty

from evorbc_ros.health import WARN, Health
from evorbc_ros.node_parameters import COMMON, spec
from evorbc_ros.nodes.common import (
    LATCHED,
    Executor,
    StartupError,
    init_ros,
    logged_startup,
    quiet_teardown,
    spin_until_stopped,
    stop_requested,
)
from evorbc_ros.nodes.diagnostics import DiagnosticsPublisher
from evorbc_ros.nodes.parameters import ParameterGuard, declare_all
from sim_bridge.rosbag_io import BagError, BagWriter, check_type

#: Messages each subscription may hold before the recorder takes them: a lockstep graph
#: publishes as fast as it answers, and a recorder that falls behind for a moment (a disk
#: flush) must lose nothing.
DEPTH = 1000
#: How often (wall s) the graph is searched for the type of a topic not yet subscribed.
DISCOVERY_PERIOD = 0.1
#: Longest time (wall s) spent taking already-delivered messages after a stop request.
DRAIN_LIMIT = 2.0
#: Quiet time (wall s) that ends the drain: on a loaded machine the middleware's threads
#: may hand over a delivered message only a few ms after it arrived.
DRAIN_QUIET = 0.05
#: ``pkg/msg/Name``: the message types a subscription can be made for.
MESSAGE_TYPE = re.compile(r"([A-Za-z][A-Za-z0-9_]*)/msg/([A-Za-z][A-Za-z0-9_]*)")


def message_class(msgtype: str):
    """The rclpy message class of ``msgtype`` (``pkg/msg/Name``).

    Raises:
        ValueError: not a message type name, or no such message in this installation.
    """
    match = MESSAGE_TYPE.fullmatch(msgtype)
    if match is None:
        raise ValueError(f"{msgtype!r} is not a message type (pkg/msg/Name)")
    package, name = match.groups()
    try:
        return getattr(importlib.import_module(f"{package}.msg"), name)
    except (ImportError, AttributeError):
        raise ValueError(f"message type {msgtype} is not installed") from None


def record_qos(latched: bool) -> QoSProfile:
    """Reliable, deep; transient local for a latched topic (its publisher keeps the last)."""
    return QoSProfile(
        depth=DEPTH,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
    )


#: The recorder's parameters (:mod:`evorbc_ros.node_parameters`'s way).
PARAMETERS = (
    spec("bag", "", "bag folder to create (rosbag2, MCAP storage)"),
    spec("topics", (), "topics to record"),
    spec("types", (), "their message types (pkg/msg/Name), in order; empty: from the graph"),
    spec("latched", ("goal",), "topics with a latched publisher (recorded transient local)"),
    *COMMON,
)


class RecorderNode(Node):
    """Subscribes the given topics raw and writes every message to one bag."""

    def __init__(self, **kwargs) -> None:
        super().__init__("recorder", **kwargs)
        with logged_startup(self):
            p = declare_all(self, PARAMETERS, "at start-up", {})
            bag, topics, types, latched = (p[k] for k in ("bag", "topics", "types", "latched"))
            if not bag:
                raise StartupError("parameter bag must name the bag folder to create")
            if not topics:
                raise StartupError("parameter topics must list the topics to record")
            if types and len(types) != len(topics):
                raise StartupError(
                    f"parameter types must give one type per topic ({len(topics)}), "
                    f"got {len(types)}"
                )
            names = [self._resolve(t, "topics") for t in topics]
            if len(set(names)) != len(names):
                raise StartupError(f"parameter topics lists a topic twice: {topics}")
            self.latched = {self._resolve(t, "latched") for t in latched}
            self.wanted = dict(zip(names, types or [""] * len(names), strict=True))
            for msgtype in filter(None, self.wanted.values()):
                self._check_type(msgtype, "parameter types")
            try:
                self.bag = BagWriter(bag)
            except BagError as e:
                raise StartupError(f"parameter bag: {e}") from None
        ParameterGuard(self, PARAMETERS, "at start-up")
        self.diagnostics = DiagnosticsPublisher(self, p["diagnostics_period"], self.health)
        self.subs = {}
        self.matched: set[str] = set()  # topics whose subscription has matched a publisher
        # Latched: a bridge that starts waiting after it was sent still gets it.
        self.ready_pub = self.create_publisher(Empty, "~/ready", LATCHED)
        self.ready_topic = self.ready_pub.topic_name
        self.written = 0  # messages written, for the drain after a stop request
        self.pending = [t for t, msgtype in self.wanted.items() if not msgtype]
        self.refused: set[str] = set()  # graph types that cannot be recorded, logged once
        for topic, msgtype in self.wanted.items():
            if msgtype:
                self.subscribe(topic, msgtype)
        if self.pending:
            self.get_logger().info(
                f"waiting for a publisher of {', '.join(self.pending)} to learn the type"
            )
            # Wall time: a timer on the simulated clock would stand still until /clock runs.
            steady = Clock(clock_type=ClockType.STEADY_TIME)
            self.discovery = self.create_timer(DISCOVERY_PERIOD, self.discover, clock=steady)
        self.get_logger().info(f"recording {len(self.wanted)} topics into {bag}")

    def _resolve(self, topic: str, parameter: str) -> str:
        """The fully qualified name of ``topic`` (namespace and remappings applied)."""
        try:
            return self.resolve_topic_name(topic)
        except Exception:  # rcl reports an invalid name as a generic error
            raise StartupError(f"parameter {parameter}: {topic!r} is not a topic name") from None

    @staticmethod
    def _check_type(msgtype: str, where: str) -> None:
        """Refuse a type that cannot be subscribed here or described in the bag."""
        try:
            message_class(msgtype)
            check_type(msgtype)
        except (ValueError, BagError) as e:
            raise StartupError(f"{where}: {e}") from None

    def subscribe(self, topic: str, msgtype: str) -> None:
        """Add ``topic`` to the bag and subscribe it raw."""
        latched = topic in self.latched
        self.bag.add_topic(topic, msgtype, latched=latched, depth=1 if latched else DEPTH)
        self.subs[topic] = self.create_subscription(
            message_class(msgtype),
            topic,
            lambda raw, t=topic: self.on_message(t, raw),
            record_qos(latched),
            raw=True,
            event_callbacks=SubscriptionEventCallbacks(
                matched=lambda info, t=topic: self.on_matched(t, info.current_count)
            ),
        )

    def on_matched(self, topic: str, publishers: int) -> None:
        """Note the first publisher matched on ``topic``; say ready once every topic has one.

        A publisher that started after this node learns of it late (a DDS participant
        announces itself to those started earlier only every few seconds), and what it
        publishes before the match is not recorded. Whoever must not lose the first
        messages (the lockstep bridge) waits for ``~/ready``.
        """
        if publishers < 1 or topic in self.matched:
            return
        self.matched.add(topic)
        self.get_logger().info(f"{topic}: publisher matched")
        if len(self.matched) == len(self.wanted):
            self.get_logger().info(f"every topic has a publisher; ready on {self.ready_topic}")
            self.ready_pub.publish(Empty())

    def on_message(self, topic: str, raw: bytes) -> None:
        """Write one message, logged at the node's clock (simulated with use_sim_time)."""
        self.bag.write(topic, self.get_clock().now().nanoseconds, raw)
        self.written += 1

    def discover(self) -> None:
        """Subscribe the topics without a given type once a publisher shows theirs."""
        known = dict(self.get_topic_names_and_types())
        for topic in list(self.pending):
            found = known.get(topic, [])
            if len(found) != 1:
                if len(found) > 1 and topic not in self.refused:
                    self.refused.add(topic)
                    self.get_logger().error(
                        f"{topic} is published with several types ({', '.join(found)}); "
                        "not recorded: give its type in parameter types"
                    )
                continue
            self.pending.remove(topic)
            try:
                self._check_type(found[0], topic)
            except StartupError as e:
                self.get_logger().error(f"not recorded: {e}")
                continue
            self.subscribe(topic, found[0])
            self.get_logger().info(f"recording {topic} ({found[0]})")
        if not self.pending:
            self.discovery.cancel()

    def drain(self) -> None:
        """Take the messages already delivered when the stop came, within DRAIN_LIMIT.

        The last messages of a run (the bridge's final state, the last choice) may still
        wait in the subscriptions when the graph is stopped all at once. (The lockstep
        bridge ends only once its state messages are acknowledged, that is held here.)
        """
        executor = Executor(context=self.context)
        executor.add_node(self)
        deadline = time.monotonic() + DRAIN_LIMIT
        idle = 0
        try:
            # A spin that writes nothing may have run the clock or the timer instead; three
            # in a row, each after waiting DRAIN_QUIET, mean nothing is left.
            while idle < 3 and time.monotonic() < deadline and self.context.ok():
                before = self.written
                executor.spin_once(timeout_sec=DRAIN_QUIET)
                idle = idle + 1 if self.written == before else 0
        finally:
            executor.remove_node(self)
            executor.shutdown()

    def close_bag(self) -> bool:
        """Finish the bag (it gets its final name); False if it could not be finished."""
        bag, self.bag = getattr(self, "bag", None), None
        if bag is None:
            return True
        try:
            path = bag.close()
        except BagError as e:
            self.get_logger().error(str(e))
            return False
        counts = ", ".join(f"{t} {n}" for t, n in bag.counts.items())
        self.get_logger().info(f"wrote {path}: {counts or 'no topics'}")
        return True

    def health(self, now: float) -> Health:
        """Messages written, topics still without a publisher."""
        h = Health()
        h.add("messages written", self.written)
        missing = sorted(set(self.wanted) - self.matched)
        h.add("topics without a publisher", ", ".join(missing) or "none")
        if missing:
            h.worse(WARN, f"no publisher yet on {', '.join(missing)}")
        return h

    def destroy_node(self) -> None:
        """Close the bag, then the node."""
        self.close_bag()
        super().destroy_node()


def main(argv=None) -> int:
    """Record until SIGINT or SIGTERM; then 0, or 1 if the bag could not be written.

    Status 2 if it cannot start (one FATAL line). The steps of
    :func:`evorbc_ros.nodes.common.run_node`, with the drain before the bag is closed.
    """
    status = init_ros(argv)
    if status is not None:
        return status
    node, status = None, 0
    try:
        node = RecorderNode()
        spin_until_stopped(node)
        node.drain()
    except StartupError as e:
        if not e.logged:
            print(f"error: {e}", file=sys.stderr)
        status = 2
    except BagError as e:  # a write failed (disk full): what was written stays partial
        node.get_logger().error(f"{e}; recording stopped")
        node.bag.abort()
        node.bag, status = None, 1
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    except Exception:
        if not stop_requested():
            raise
    finally:
        quiet_teardown()
        if node is not None:
            status = status or (0 if node.close_bag() else 1)
            node.destroy_node()
        rclpy.try_shutdown()
    return status


if __name__ == "__main__":
    sys.exit(main())
