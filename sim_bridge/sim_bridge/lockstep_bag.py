"""A lockstep run's bag as the player needs it: the goal, the cycles, the recorded choices.

In lockstep (docs/design.md section 9) the bridge publishes, for each cycle at simulated
time t, ``/clock`` = t and a scan and an odometry stamped t; the arbitrator answers with
exactly one ``evorbc/primitive``. So the k-th scan, the k-th odometry and the k-th recorded
choice belong to cycle k, and each pair is checked by its stamps. The episode's final state
(published after the last step, for listeners) also draws a choice, which a recording
stopped with the graph may miss: a bag holds one choice per cycle, or one fewer. When the
graph stops, the arbitrator's deactivation sends one more, empty primitive labelled
``deactivated`` (stop the robot): it belongs to no cycle and is left out.

Pure data (rosbags and numpy): the ROS side is :mod:`sim_bridge.player`.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from evorbc_ros.arbitration import DEACTIVATED
from sim_bridge.rosbag_io import BagError, BagReader, decode

#: What each role's topic must carry.
TYPES = {
    "scan": "sensor_msgs/msg/LaserScan",
    "odom": "nav_msgs/msg/Odometry",
    "goal": "geometry_msgs/msg/PointStamped",
    "primitive": "std_msgs/msg/Float64MultiArray",
    "clock": "rosgraph_msgs/msg/Clock",
}


@dataclass(frozen=True)
class Cycle:
    """One lockstep cycle: its stamp and the recorded messages that start it (CDR bytes).

    ``clock`` is None when the bag has no ``/clock`` message for this time.
    """

    stamp_ns: int
    clock: bytes | None
    scan: bytes
    odom: bytes

    @property
    def seconds(self) -> float:
        """The cycle's simulated time (s)."""
        return self.stamp_ns * 1e-9


@dataclass(frozen=True)
class LockstepRecording:
    """What a lockstep run's bag holds for playback.

    Attributes:
        topics: fully qualified topic of each role (``scan``, ``odom``, ``goal``,
            ``primitive``, ``clock``).
        goal: the first goal message (CDR bytes).
        cycles: the cycles, in order.
        choices: the recorded primitives' genes (each a float64 vector, empty for "stop"),
            in order; None if the bag has no primitive topic.
    """

    topics: dict[str, str]
    goal: bytes
    cycles: list[Cycle]
    choices: list[np.ndarray] | None


def role_topics(namespace: str = "") -> dict[str, str]:
    """The fully qualified topic of each role in ``namespace`` (``/clock`` stays global)."""
    prefix = f"/{namespace.strip('/')}" if namespace.strip("/") else ""
    return {
        "scan": f"{prefix}/scan",
        "odom": f"{prefix}/odom",
        "goal": f"{prefix}/goal",
        "primitive": f"{prefix}/evorbc/primitive",
        "clock": "/clock",
    }


def load_recording(path: str | os.PathLike, namespace: str = "") -> LockstepRecording:
    """Read the lockstep cycles of the bag at ``path``.

    Raises:
        BagError: one line: not a bag, a missing or mistyped topic, scans and odometry
            that do not pair up.
    """
    topics = role_topics(namespace)
    with BagReader(path) as bag:
        for role in ("scan", "odom", "goal"):
            if topics[role] not in bag.topics:
                raise BagError(f"{path}: no {topics[role]} in the bag; it cannot be played")
        for role, topic in topics.items():
            found = bag.topics.get(topic)
            if found is not None and found.msgtype != TYPES[role]:
                raise BagError(f"{path}: {topic} holds {found.msgtype}, expected {TYPES[role]}")
        by_topic: dict[str, list[bytes]] = {t: [] for t in topics.values()}
        for message in bag.messages(topics.values()):
            by_topic[message.topic].append(message.raw)
    if not by_topic[topics["goal"]]:
        raise BagError(f"{path}: {topics['goal']} has no message")
    clocks = {}
    for raw in by_topic[topics["clock"]]:
        clock = decode(raw, TYPES["clock"], topics["clock"]).clock
        clocks.setdefault(clock.sec * 1_000_000_000 + clock.nanosec, raw)
    cycles = pair_cycles(by_topic[topics["scan"]], by_topic[topics["odom"]], clocks, topics)
    if not cycles:
        raise BagError(f"{path}: {topics['scan']} has no message")
    choices = None
    if topics["primitive"] in bag.topics:
        messages = [
            decode(raw, TYPES["primitive"], topics["primitive"])
            for raw in by_topic[topics["primitive"]]
        ]
        choices = [np.asarray(m.data, np.float64) for m in messages if not _deactivation(m)]
    return LockstepRecording(topics, by_topic[topics["goal"]][0], cycles, choices)


def _deactivation(msg) -> bool:
    """Whether a primitive message is the arbitrator's deactivation (empty, labelled so)."""
    return len(msg.data) == 0 and bool(msg.layout.dim) and msg.layout.dim[0].label == DEACTIVATED


def pair_cycles(
    scans: list[bytes], odoms: list[bytes], clocks: dict[int, bytes], topics: dict[str, str]
) -> list[Cycle]:
    """The k-th scan with the k-th odometry, checked by their header stamps.

    Raises:
        BagError: the counts or the stamps disagree (an incomplete or mixed recording).
    """
    if len(scans) != len(odoms):
        raise BagError(
            f"{len(scans)} messages on {topics['scan']} but {len(odoms)} on {topics['odom']}: "
            "not one lockstep cycle each"
        )
    cycles = []
    for k, (scan, odom) in enumerate(zip(scans, odoms, strict=True)):
        stamps = [
            _stamp_ns(decode(raw, TYPES[role], topics[role]).header.stamp)
            for raw, role in ((scan, "scan"), (odom, "odom"))
        ]
        if stamps[0] != stamps[1]:
            raise BagError(
                f"cycle {k}: {topics['scan']} is stamped {stamps[0] * 1e-9:.3f} s but "
                f"{topics['odom']} {stamps[1] * 1e-9:.3f} s"
            )
        cycles.append(Cycle(stamps[0], clocks.get(stamps[0]), scan, odom))
    return cycles


def _stamp_ns(stamp) -> int:
    """A builtin_interfaces/Time in ns."""
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def check_choices(recording: LockstepRecording, path: str | os.PathLike) -> None:
    """Refuse a bag whose recorded choices do not belong one to one to its cycles.

    One choice per cycle, or one fewer (the final state's may be missing; see the module
    docstring). Anything else is a recording that missed part of the run, such as a
    recorder that matched the graph's publishers only after the first cycles.

    Raises:
        BagError: one line with both counts and the first cycle's time.
    """
    n, m = len(recording.cycles), len(recording.choices or [])
    if not n - 1 <= m <= n:
        raise BagError(
            f"{path}: {m} recorded choices for {n} cycles (the first at "
            f"t = {recording.cycles[0].seconds:.3f} s); a complete lockstep recording has "
            "one per cycle"
        )


def first_difference(
    recorded: list[np.ndarray], played: list[np.ndarray], cycles: list[Cycle]
) -> str:
    """Compare the choices bit for bit; "" if equal, else one line naming the first difference.

    ``recorded`` may be one shorter than ``played`` (:func:`check_choices`); only the cycles
    it covers are compared.
    """
    for k, (want, got) in enumerate(zip(recorded, played, strict=False)):
        # Bit for bit: tobytes() tells -0.0 from 0.0 and compares NaNs by their bits.
        if want.shape != got.shape or want.tobytes() != got.tobytes():
            return (
                f"choices differ at cycle {k} (t = {cycles[k].seconds:.3f} s): recorded "
                f"{_genes(want)}, played {_genes(got)}"
            )
    if len(played) < len(recorded):
        return f"{len(recorded)} choices recorded but only {len(played)} played"
    return ""


def _genes(values: np.ndarray) -> str:
    """A gene vector with every digit (Python's shortest round-trip repr)."""
    return "[" + ", ".join(repr(float(v)) for v in values) + "]"
