"""How much one input may hold, and how to allow more (docs/design.md section 12).

A file from someone else can ask for any amount of work: three million primitives, a
hundred-thousand-node chain, a maze of 200,000 walls. Each limit here is far above any real
file of its kind and well within what a 2-core, 24 GiB machine loads in seconds, and it is
checked from the file's counts before the work starts. A file over a limit is refused in one
line that names the limit and the environment variable that raises it for a run, so a user
with a genuinely larger file is never stuck.
"""

from __future__ import annotations

import os
from dataclasses import dataclass


@dataclass(frozen=True)
class Limit:
    """An upper bound on a count in an input, raisable through an environment variable.

    Attributes:
        what: the counted things, plural, as a message reads them ("primitives").
        env: the environment variable that overrides ``default`` (``EVORBC_MAX_...``).
        default: the bound (inclusive).
    """

    what: str
    env: str
    default: int

    def value(self) -> int:
        """The bound in force: ``$env`` if set, else ``default``.

        Raises:
            ValueError: ``$env`` is set but not a positive integer (one line naming it).
        """
        raw = os.environ.get(self.env)
        if raw is None or raw.strip() == "":
            return self.default
        try:
            value = int(raw.replace("_", "").replace(",", ""))
        except ValueError:
            value = 0
        if value < 1:
            raise ValueError(f"{self.env} must be a positive integer, got {raw!r}")
        return value

    def problem(self, count: int, where: str = "") -> str | None:
        """Why ``count`` is too many, in one line without the file name; None if it is not.

        Args:
            count: the number the input holds or asks for.
            where: what holds them, for the message ("in the archive", "in
                network.nodes"); empty for none.
        """
        try:
            limit = self.value()
        except ValueError as e:
            return str(e)
        if count <= limit:
            return None
        place = f" {where}" if where else ""
        return (
            f"{count:,} {self.what}{place}, more than the limit of {limit:,}; if that is "
            f"intended, raise it with {self.env}={_suggest(count)}"
        )

    def check(self, count: int, source: str, error: type[Exception], where: str = "") -> None:
        """Raise ``error("<source>: <problem>")`` if ``count`` is over the limit."""
        problem = self.problem(count, where)
        if problem:
            raise error(f"{source}: {problem}")


def _suggest(count: int) -> int:
    """A round number at least ``count``: 3,000,017 -> 4,000,000."""
    step = 10 ** max(len(str(count)) - 1, 0)
    return -(-count // step) * step


# The limits, by format. Real files: the paper's repertoires hold up to about 45,000
# primitives and a hexapod run 200,000; evolved networks hold tens of nodes; the shipped
# mazes hold tens of walls and generated ones a few hundred.
#: Primitives in one repertoire file.
PRIMITIVES = Limit("primitives", "EVORBC_MAX_PRIMITIVES", 1_000_000)
#: Cells of one repertoire's archive (the grid's dims multiplied, or a CVT's cells).
ARCHIVE_CELLS = Limit("cells", "EVORBC_MAX_ARCHIVE_CELLS", 10_000_000)
#: Nodes (hidden and output) in one network.
NETWORK_NODES = Limit("nodes", "EVORBC_MAX_NETWORK_NODES", 10_000)
#: Connections in one network.
NETWORK_CONNECTIONS = Limit("connections", "EVORBC_MAX_NETWORK_CONNECTIONS", 200_000)
#: Walls in one maze.
MAZE_WALLS = Limit("walls", "EVORBC_MAX_MAZE_WALLS", 50_000)
#: Bytes of the arrays in one checkpoint once inflated (a 16 GiB zip bomb is a few MB).
CHECKPOINT_ARRAY_BYTES = Limit("bytes of arrays", "EVORBC_MAX_CHECKPOINT_BYTES", 4 << 30)
#: Levels of nesting in a JSON or YAML file (ours nest fewer than 10).
NESTING = Limit("levels of nesting", "EVORBC_MAX_NESTING", 100)
