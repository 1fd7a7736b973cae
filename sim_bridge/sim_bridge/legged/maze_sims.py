"""Per-maze PyBullet simulations a worker keeps, for fixed and generated mazes alike.

A legged maze task's job names its maze by index into the task's own mazes (sent to the
workers once), or carries a generated maze (training on generated mazes, docs/design.md
section 22): a new set every generation. A worker keeps a simulation per maze; those of
generated mazes are closed once more than :data:`KEEP` are open (a simulation holds the
maze's walls and the robot, a few MB).
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Sequence
from typing import Any

from sim_bridge.maze import Maze

#: Simulations of generated mazes a worker keeps open.
KEEP = 16


class MazeSims:
    """Simulations by maze, built on first use by ``make(boxes)``.

    Args:
        mazes: the task's own mazes (a job's ``int`` maze names one).
        make: builds a simulation of a maze's wall boxes ``(n, 6)``; it has ``close()``.

    """

    def __init__(self, mazes: Sequence[Maze], make: Callable[[Any], Any]):
        self.mazes = mazes
        self.make = make
        self.fixed: dict[int, Any] = {}
        self.generated: OrderedDict[str, Any] = OrderedDict()

    def get(self, which: int | Maze) -> tuple[Maze, Any]:
        """``(maze, simulation)`` for a task maze's index or a generated maze."""
        if not isinstance(which, Maze):
            if which not in self.fixed:
                self.fixed[which] = self.make(self.mazes[which].boxes)
            return self.mazes[which], self.fixed[which]
        sim = self.generated.get(which.name)
        if sim is None:
            sim = self.make(which.boxes)
            self.generated[which.name] = sim
            if len(self.generated) > KEEP:
                self.generated.popitem(last=False)[1].close()
        else:
            self.generated.move_to_end(which.name)
        return which, sim

    def values(self) -> list:
        """Every open simulation."""
        return [*self.fixed.values(), *self.generated.values()]

    def clear(self) -> None:
        """Forget every simulation (the caller closed them)."""
        self.fixed.clear()
        self.generated.clear()
