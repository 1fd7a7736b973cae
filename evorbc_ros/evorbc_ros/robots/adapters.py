"""A layer's own adapters for robots, by family: how the simulation and the search find theirs.

The onboard record (:class:`~evorbc_ros.robots.record.Robot`) holds onboard facts only.
Each layer above it (the simulation, the search) keeps an :class:`AdapterTable` of its own
code per robot family: a frozen dataclass of import paths or objects, looked up by the
record's :attr:`~Robot.adapter_key` (its ``family``, else its name). This module knows
no layer: each layer builds its table with its built-in families and its entry-point
group (docs/design.md section 19).

Where adapters come from, first found wins:

* registered in this process (:meth:`AdapterTable.register`, a script's own robot);
* the layer's built-in families;
* plugins: entry points in the layer's group, named by family, each giving the adapters
  or a callable returning them; looked for only when a family is not built in, once per
  process, a broken one reported in one line and left out;

and, for a robot declared the deprecated way, the factory fields of its record override
its family's (:data:`~evorbc_ros.robots.record.LEGACY_FIELDS`).
"""

from __future__ import annotations

import dataclasses
import sys
from collections.abc import Callable, Mapping
from typing import Any, Generic, TypeVar

from evorbc_ros.robots.record import Robot, RobotError, load_path, one_line

A = TypeVar("A")


def report(problem: str) -> None:
    """Print a problem as evorbc's one-line warning on stderr."""
    print(f"evorbc: warning: {problem}", file=sys.stderr)


class AdapterTable(Generic[A]):
    """One layer's adapters by robot family.

    Args:
        kind: the layer's adapters dataclass; its fields are import paths
            (``"package.module:attribute"``, imported when used) or the objects themselves.
        group: the entry-point group plugins declare this layer's adapters in.
        builtin: the layer's own families: family -> adapters.
        legacy: the record's deprecated factory fields this layer reads, by the adapters'
            field names; those a record sets override its family's.
        report: called once with each broken plugin's one-line problem.

    """

    def __init__(
        self,
        kind: type[A],
        group: str,
        builtin: Mapping[str, A],
        legacy: tuple[str, ...] = (),
        report: Callable[[str], None] = report,
    ) -> None:
        self.kind = kind
        self.group = group
        self.legacy = legacy
        self.report = report
        self._builtin = dict(builtin)
        self.reset()

    def reset(self) -> None:
        """Forget adapters registered in this process and plugins found (tests)."""
        self._registered: dict[str, A] = {}
        self._plugins: dict[str, A] | None = None
        #: One line per adapter plugin that could not be used.
        self.problems: list[str] = []

    def register(self, family: str, adapters: A) -> None:
        """Use ``adapters`` for robots of ``family`` in this process (before any other)."""
        self._check(adapters, f"adapters for family {family}")
        self._registered[family] = adapters

    def _check(self, adapters: Any, where: str) -> None:
        if not isinstance(adapters, self.kind):
            raise RobotError(
                f"{where}: expected a {self.kind.__name__}, got {type(adapters).__name__}"
            )

    def _found(self, family: str) -> A | None:
        for table in (self._registered, self._builtin):
            if family in table:
                return table[family]
        if self._plugins is None:
            self._plugins = self._read_plugins()
        return self._plugins.get(family)

    def _read_plugins(self) -> dict[str, A]:
        from importlib.metadata import entry_points

        found: dict[str, A] = {}
        for point in sorted(entry_points(group=self.group), key=lambda p: p.name):
            dist = getattr(point, "dist", None)
            origin = f" in {dist.name} {dist.version}" if dist is not None else ""
            where = f"{self.group} plugin {point.name} ({point.value}{origin})"
            try:
                loaded = point.load()
                adapters = loaded if isinstance(loaded, self.kind) else loaded()
                self._check(adapters, where)
            except Exception as e:  # whatever a plugin does, it must not stop evorbc
                problem = f"{where} cannot be loaded ({one_line(e)}); left out"
                self.problems.append(problem)
                self.report(problem)
                continue
            found.setdefault(point.name, adapters)
        return found

    def adapters(self, robot: Robot) -> A:
        """The adapters of ``robot`` in this layer (its deprecated fields override them).

        Raises:
            RobotError: one line naming the robot, its family and the entry-point group
                when this layer has no adapters for it.

        """
        given = {f: getattr(robot, f) for f in self.legacy if getattr(robot, f)}
        found = self._found(robot.adapter_key)
        if found is not None:
            return dataclasses.replace(found, **given) if given else found
        try:
            if given:
                return self.kind(**given)
        except TypeError:  # a required adapter the record does not give either
            pass
        raise RobotError(
            f"robot {robot.name}: no adapters for its family {robot.adapter_key!r} in "
            f"{self.group} (docs/your-robot.md)"
        )

    def load(self, robot: Robot, field: str) -> Any:
        """One adapter of ``robot``, imported now if it is an import path (None if unset).

        Raises:
            RobotError: no adapters, or one that cannot be imported, in one line.

        """
        value = getattr(self.adapters(robot), field)
        if isinstance(value, str):
            return load_path(value, f"robot {robot.name}: its {field}") if value else None
        return value
