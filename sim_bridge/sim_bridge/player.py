"""``evorbc-play``: feed a recorded lockstep run into the evorbc nodes, cycle by cycle.

``python -P -m sim_bridge.player BAG [--compare] [--timeout S] [--namespace NS]``

Plays a bag's goal, ``/clock``, ``scan`` and ``odom`` (:mod:`sim_bridge.lockstep_bag`) into
running ``laser_sensor``, ``radar_sensor`` and ``arbitrator`` nodes, with no bridge, in
lockstep as the bridge drives them (docs/design.md section 9): the goal first (latched),
then for each cycle its ``/clock``, scan and odometry, and the next cycle only once the
arbitrator's one ``evorbc/primitive`` for it has arrived. Messages go out as the CDR bytes
recorded. The nodes must be freshly started: a recurrent network's state and the radar's
motion window start with the node.

With ``--compare`` the choices are checked bit for bit against the bag's recorded
``evorbc/primitive``: status 0 and "N of N choices equal", or status 1 and one line naming
the first differing cycle. Status 1 too when the graph does not answer within
``--timeout`` s (every wait is bounded by it); 2 for a bad bag or option (one line, no
traceback); 130 on Ctrl-C.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
import rclpy
from geometry_msgs.msg import PointStamped
from nav_msgs.msg import Odometry
from rclpy.duration import Duration
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64MultiArray

from evorbc_ros.nodes.common import (
    LATCHED,
    RELIABLE,
    STOP_POLL,
    Executor,
    init_ros,
    quiet_teardown,
    running,
)
from sim_bridge.bridge_node import stamp
from sim_bridge.cli_support import OneLineParser, report_unexpected
from sim_bridge.lockstep_bag import (
    LockstepRecording,
    check_choices,
    first_difference,
    load_recording,
)
from sim_bridge.rosbag_io import BagError

PROG = "evorbc-play"
#: Exit statuses besides 0.
DIFFERENT, BAD_INPUT, INTERRUPTED = 1, 2, 130


class PlaybackError(Exception):
    """The graph did not answer as lockstep requires; the message says where."""


def parse_args(argv=None) -> argparse.Namespace:
    """Command-line options of ``evorbc-play``."""
    p = OneLineParser(
        prog=PROG,
        description="Play a recorded lockstep run into the running laser_sensor, "
        "radar_sensor and arbitrator nodes and collect the arbitrator's choices.",
    )
    p.add_argument("bag", help="the bag folder (rosbag2, e.g. recorded by evorbc-sim --bag)")
    p.add_argument(
        "--compare",
        action="store_true",
        help="check the choices against the bag's recorded evorbc/primitive (bit for bit)",
    )
    p.add_argument(
        "--timeout",
        type=positive_seconds,
        default=30.0,
        help="longest wait (s) for the nodes at the start and for each choice (default 30)",
    )
    p.add_argument(
        "--namespace", default="", help="namespace the bag's topics and the nodes are in"
    )
    return p.parse_args(argv)


def positive_seconds(text: str) -> float:
    """Argparse type: a finite number of seconds > 0."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (np.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a number of seconds > 0, got {text!r}")
    return value


#: s of wall time between the graph's match and the first cycle (see Player.connect).
MATCH_GRACE = 0.3


class Player(Node):
    """Publishes a recording's cycles in lockstep and collects the arbitrator's choices."""

    def __init__(self, recording: LockstepRecording, timeout: float) -> None:
        super().__init__("evorbc_player")
        self.recording, self.timeout = recording, timeout
        topics = recording.topics
        self.clock_pub = self.create_publisher(Clock, topics["clock"], RELIABLE)
        self.scan_pub = self.create_publisher(LaserScan, topics["scan"], RELIABLE)
        self.odom_pub = self.create_publisher(Odometry, topics["odom"], RELIABLE)
        self.goal_pub = self.create_publisher(PointStamped, topics["goal"], LATCHED)
        self.choices: list[np.ndarray] = []  # genes (float64 vectors), one per cycle
        self.choice_sub = self.create_subscription(
            Float64MultiArray,
            topics["primitive"],
            lambda msg: self.choices.append(np.asarray(msg.data, np.float64)),
            RELIABLE,
        )
        self.executor_ = Executor(context=self.context)
        self.executor_.add_node(self)

    def wait_until(self, condition, what) -> None:
        """Spin until ``condition()``; after the timeout, PlaybackError saying ``what()``.

        Each wait is at most STOP_POLL long, so a stop request is seen at once.
        """
        deadline = time.monotonic() + self.timeout
        while not condition():
            if not running():
                raise KeyboardInterrupt
            if time.monotonic() >= deadline:
                raise PlaybackError(f"{what()} within {self.timeout:g} s")
            self.executor_.spin_once(timeout_sec=STOP_POLL)

    def connect(self) -> None:
        """Wait until every endpoint of the player is matched, then hand the goal over.

        A publisher that has matched a subscription delivers every later message to it
        reliably, even if the subscription's side completes the match a moment after. The
        goal is acknowledged before the first cycle, so the radar node holds it when the
        first odometry comes (it takes its goal subscriptions' messages first).
        """
        topics = self.recording.topics
        counts = {
            topics["scan"]: self.scan_pub.get_subscription_count,
            topics["odom"]: self.odom_pub.get_subscription_count,
            topics["goal"]: self.goal_pub.get_subscription_count,
            topics["primitive"]: self.choice_sub.get_publisher_count,
        }

        def unmatched() -> list[str]:
            return [topic for topic, count in counts.items() if count() == 0]

        self.wait_until(lambda: not unmatched(), lambda: f"no node on {', '.join(unmatched())}")
        self.goal_pub.publish(self.recording.goal)
        if not self.goal_pub.wait_for_all_acked(Duration(seconds=self.timeout)):
            raise PlaybackError(
                f"{topics['goal']}: the goal was not taken within {self.timeout:g} s"
            )
        # The sensor nodes take scan and odom best effort (sensor-data QoS): a message
        # that reaches a reader before the reader's side of the match completes is
        # dropped, not resent, and cycle 0 would then never be answered (seen once under
        # load 9). Give the far ends the moment the bridge gives them (bridge_node
        # wait_for_graph, 0.3 s of wall time) before the first cycle.
        until = time.monotonic() + MATCH_GRACE
        while time.monotonic() < until:
            if not running():
                raise KeyboardInterrupt
            self.executor_.spin_once(timeout_sec=STOP_POLL)

    def play(self) -> list[np.ndarray]:
        """Every cycle in lockstep; returns the arbitrator's choice for each."""
        for k, cycle in enumerate(self.recording.cycles):
            self.clock_pub.publish(cycle.clock or Clock(clock=stamp(cycle.seconds)))
            self.scan_pub.publish(cycle.scan)
            self.odom_pub.publish(cycle.odom)
            self.wait_until(
                lambda k=k: len(self.choices) > k,
                lambda k=k, t=cycle.seconds: f"no choice for cycle {k} (t = {t:.3f} s)",
            )
            if len(self.choices) > k + 1:
                raise PlaybackError(
                    f"two choices for cycle {k} (t = {cycle.seconds:.3f} s): another "
                    f"publisher on {self.recording.topics['primitive']}?"
                )
        return self.choices

    def destroy_node(self) -> None:
        """Stop the executor, then the node."""
        self.executor_.remove_node(self)
        self.executor_.shutdown()
        super().destroy_node()


def main(argv=None) -> int:
    """Play a bag (see the module docstring for the statuses)."""
    args = parse_args(argv)
    try:
        return run(args)
    except BagError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return BAD_INPUT
    except PlaybackError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return DIFFERENT
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return INTERRUPTED
    except Exception as e:
        return report_unexpected(PROG, e)


def run(args: argparse.Namespace) -> int:
    """Read the bag, play it, report (and compare)."""
    recording = load_recording(args.bag, args.namespace)
    if args.compare:
        if recording.choices is None:
            raise BagError(f"{args.bag}: no {recording.topics['primitive']} to compare with")
        check_choices(recording, args.bag)  # before playing: a bad bag costs nothing
    played = play(recording, args.timeout)
    n = len(recording.cycles)
    if not args.compare:
        print(f"played {n} cycles: {len(played)} choices")
        return 0
    difference = first_difference(recording.choices, played, recording.cycles)
    if difference:
        print(f"{PROG}: {difference}", file=sys.stderr)
        return DIFFERENT
    m = len(recording.choices)
    note = "" if m == n else " (the bag has no choice for the last cycle)"
    print(f"{m} of {m} choices equal{note}")
    return 0


def play(recording: LockstepRecording, timeout: float) -> list[np.ndarray]:
    """Bring rclpy up, play every cycle, and shut rclpy down (signals as in the nodes)."""
    status = init_ros([])
    if status is not None:
        raise KeyboardInterrupt  # without arguments, only a signal stops rclpy.init
    node = None
    try:
        node = Player(recording, timeout)
        node.connect()
        return node.play()
    except rclpy.executors.ExternalShutdownException:
        raise KeyboardInterrupt from None
    finally:
        quiet_teardown()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
