"""rosbag2 bags in MCAP storage, written and read with the pure-Python ``rosbags`` library.

rosbag2 itself is not on PyPI (docs/design.md section 10), so the recorder and the player
use ``rosbags``, which writes the same layout: a folder ``DIR`` holding ``metadata.yaml``
and ``DIR.mcap``. Messages are stored as the raw CDR bytes the middleware delivered, never
decoded and encoded again, and each topic's schema in the MCAP file is the full message
definition from rosbags' ROS 2 Jazzy type store, so ``ros2 bag info``, ``ros2 bag play``,
Foxglove and the ``mcap`` tools open a bag without the evorbc code.

Two choices make a bag safe to trust:

* The metadata is version 8, Jazzy's. Version 9 (Kilted) writes each topic's QoS as a YAML
  list, which Jazzy's rosbag2 cannot parse; it reads version 8 and every earlier one.
* A bag is written into ``DIR.partial/DIR`` and renamed to ``DIR`` when it is closed, so a
  folder called ``DIR`` is always a finished bag. rosbags alone writes ``metadata.yaml``
  last, but into ``DIR`` itself, where a recorder that died would leave a folder that looks
  like a bag and blocks the next recording under that name. A ``DIR.partial`` left behind
  holds an MCAP file without its summary (``mcap recover`` rescues its messages); it is
  refused, never overwritten, and reading it says what it is. Renaming a folder onto an
  existing one replaces it only if that one is empty, so a user's bag is never lost.
"""

from __future__ import annotations

import contextlib
import functools
import os
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import Reader, ReaderError, StoragePlugin, Writer, WriterError
from rosbags.typesys import Stores, get_typestore

#: rosbag2 metadata version of the bags written (Jazzy's; see the module docstring).
METADATA_VERSION = 8
#: Suffix of the folder a bag is written into until it is closed.
PARTIAL = ".partial"


class BagError(Exception):
    """A bag cannot be written or read; the message names the folder and the problem."""


@functools.cache
def typestore():
    """The ROS 2 Jazzy message definitions of rosbags' type store (loaded once)."""
    return get_typestore(Stores.ROS2_JAZZY)


def check_type(msgtype: str) -> None:
    """Refuse a message type whose definition the bag could not carry.

    Raises:
        BagError: ``msgtype`` (``pkg/msg/Name``) is not a ROS 2 Jazzy type rosbags knows.
    """
    if msgtype not in typestore().types:
        raise BagError(
            f"message type {msgtype} has no definition in the ROS 2 Jazzy type store, so a bag "
            "could not describe it (evorbc's topics use common_interfaces types only)"
        )


def partial_path(path: str | os.PathLike) -> Path:
    """The folder a bag ``path`` is written into until it is closed (``DIR.partial``)."""
    path = Path(path)
    return path.with_name(path.name + PARTIAL)


def recorded_qos(latched: bool, depth: int) -> Qos:
    """The QoS a topic was recorded with, offered again by ``ros2 bag play``.

    Reliable; transient local (latched) for a topic whose late subscribers must still get
    the last message (the goal). Durations 0 mean "the middleware's default" (infinite).
    """
    zero = QosTime(0, 0)
    return Qos(
        history=QosHistory.KEEP_LAST,
        depth=depth,
        reliability=QosReliability.RELIABLE,
        durability=QosDurability.TRANSIENT_LOCAL if latched else QosDurability.VOLATILE,
        deadline=zero,
        lifespan=zero,
        liveliness=QosLiveliness.AUTOMATIC,
        liveliness_lease_duration=zero,
        avoid_ros_namespace_conventions=False,
    )


class BagWriter:
    """Writes one new bag: topics added as they become known, then messages in order.

    Use as a context manager, or call :meth:`close` (finished bag) or :meth:`abort` (the
    partial folder stays, as after a crash).
    """

    def __init__(self, path: str | os.PathLike) -> None:
        """Claim ``DIR.partial`` and open the MCAP file in it.

        Raises:
            BagError: ``path`` or ``DIR.partial`` exists, or the folder cannot be created.
        """
        self.path = Path(path)
        self.partial = partial_path(self.path)
        if self.path.exists() or self.path.is_symlink():
            raise BagError(f"{self.path} exists; a bag is never overwritten: name a new folder")
        try:
            self.path.absolute().parent.mkdir(parents=True, exist_ok=True)
            # mkdir, not exist_ok: two recorders started with one name cannot both claim it.
            self.partial.mkdir()
        except FileExistsError:
            raise BagError(
                f"{self.partial} exists: an unfinished recording (a recorder is writing it, or "
                "one stopped before closing it); remove it or name another bag"
            ) from None
        except OSError as e:
            raise BagError(f"{self.path}: cannot create the bag folder ({e.strerror})") from None
        self.writer = Writer(
            self.partial / self.path.name,
            version=METADATA_VERSION,
            storage_plugin=StoragePlugin.MCAP,
        )
        # rosbags would write null here; rosbag2 writes a map, and the tool is worth naming.
        self.writer.set_custom_data("writer", "evorbc sim_bridge.rosbag_io (rosbags)")
        try:
            self.writer.open()
        except (OSError, WriterError) as e:
            with contextlib.suppress(OSError):  # nothing was written: leave nothing behind
                (self.partial / self.path.name).rmdir()
                self.partial.rmdir()
            raise BagError(f"{self.path}: cannot open the bag ({_one_line(e)})") from None
        self.connections = {}
        self.counts: dict[str, int] = {}

    def add_topic(self, topic: str, msgtype: str, latched: bool = False, depth: int = 1) -> None:
        """Add ``topic`` (a fully qualified name, e.g. ``/scan``) of type ``msgtype``.

        ``latched`` and ``depth`` are the QoS it was recorded with (:func:`recorded_qos`).

        Raises:
            BagError: the type is unknown (:func:`check_type`) or the topic already added.
        """
        check_type(msgtype)
        if topic in self.connections:
            raise BagError(f"{self.path}: topic {topic} is already in the bag")
        self.connections[topic] = self.writer.add_connection(
            topic,
            msgtype,
            typestore=typestore(),
            offered_qos_profiles=[recorded_qos(latched, depth)],
        )
        self.counts[topic] = 0

    def write(self, topic: str, time_ns: int, raw: bytes) -> None:
        """Append one message: its CDR bytes as received, logged at ``time_ns`` (ns).

        Raises:
            BagError: the system refused the write (disk full); the bag stays partial.
        """
        try:
            self.writer.write(self.connections[topic], time_ns, raw)
        except OSError as e:
            raise BagError(f"{self.path}: cannot write ({e.strerror or e})") from None
        self.counts[topic] += 1

    def close(self) -> Path:
        """Finish the bag (index, summary, ``metadata.yaml``) and move it to its name.

        Returns:
            The bag folder.

        Raises:
            BagError: the bag could not be finished; what was written stays in the partial
                folder.
        """
        inner = self.partial / self.path.name
        try:
            self.writer.close()
            os.rename(inner, self.path)
            self.partial.rmdir()
        except OSError as e:
            raise BagError(
                f"{self.path}: cannot finish the bag ({e.strerror or e}); the recording "
                f"stays in {inner}"
            ) from None
        return self.path

    def abort(self) -> None:
        """Stop writing without finishing: the partial folder stays, as after a crash."""
        self.writer.abort()

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, kind, value, traceback) -> None:
        if kind is None:
            self.close()
        else:
            self.abort()


class Message(NamedTuple):
    """One recorded message: fully qualified topic, log time (ns) and CDR bytes."""

    topic: str
    time_ns: int
    raw: bytes


@dataclass(frozen=True)
class Topic:
    """A topic of a bag: message type and number of messages."""

    msgtype: str
    count: int


class BagReader:
    """Reads a finished bag (a rosbag2 folder, or a bare ``.mcap`` file)."""

    def __init__(self, path: str | os.PathLike) -> None:
        """Open the bag.

        Raises:
            BagError: one line: no such path, an unfinished recording, not a bag, unreadable.
        """
        self.path = Path(path)
        if not self.path.exists():
            hint = ""
            if partial_path(self.path).exists():
                hint = f" (only {partial_path(self.path)}, an unfinished recording)"
            raise BagError(f"{self.path}: no such bag{hint}")
        if self.path.name.endswith(PARTIAL) and self.path.is_dir():
            raise BagError(
                f"{self.path}: an unfinished recording, not a bag (its recorder stopped before "
                "closing it; `mcap recover` can rescue the MCAP file inside)"
            )
        if self.path.is_dir() and not (self.path / "metadata.yaml").exists():
            raise BagError(f"{self.path}: not a rosbag2 bag (no metadata.yaml)")
        try:
            self.reader = Reader(self.path)
            self.reader.open()
        except (ReaderError, OSError) as e:
            raise BagError(f"{self.path}: not a readable rosbag2 bag ({_one_line(e)})") from None
        self.topics: dict[str, Topic] = {}
        for c in self.reader.connections:
            # A topic recorded under several types or QoS has several connections.
            known = self.topics.get(c.topic)
            count = c.msgcount + (known.count if known else 0)
            self.topics[c.topic] = Topic(c.msgtype, count)

    def messages(self, topics: Iterable[str]) -> Iterator[Message]:
        """The messages of ``topics``, in log-time order (equal times: as recorded).

        Raises:
            BagError: the storage is damaged.
        """
        wanted = set(topics)
        connections = [c for c in self.reader.connections if c.topic in wanted]
        if not connections:
            return
        try:
            for connection, time_ns, raw in self.reader.messages(connections=connections):
                yield Message(connection.topic, time_ns, bytes(raw))
        except (ReaderError, OSError) as e:
            raise BagError(f"{self.path}: damaged bag ({_one_line(e)})") from None

    def close(self) -> None:
        """Close the storage files."""
        self.reader.close()

    def __enter__(self) -> BagReader:
        return self

    def __exit__(self, kind, value, traceback) -> None:
        self.close()


def decode(raw: bytes, msgtype: str, topic: str = ""):
    """A recorded message, deserialized by rosbags (plain dataclasses; nothing unpickled).

    Raises:
        BagError: the bytes are not a ``msgtype``.
    """
    try:
        return typestore().deserialize_cdr(raw, msgtype)
    except Exception as e:  # rosbags raises whatever the truncated buffer triggers
        where = f"{topic}: " if topic else ""
        raise BagError(f"{where}not a valid {msgtype} message ({_one_line(e)})") from None


def _one_line(error: Exception) -> str:
    """An exception's message on one line (rosbags' may span several)."""
    return " ".join(str(error).split()) or type(error).__name__
