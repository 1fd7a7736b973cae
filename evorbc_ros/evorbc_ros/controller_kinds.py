"""The two kinds of evolved controller, as one record each (docs/design.md section 8).

An arbitrator file's ``kind`` and ``evorbc-evolve``'s subcommand name a kind; that name is
looked up here once, where the file or option is read, and the code after asks the
record what differs instead of comparing names:

* ``evorbc``: the paper's arbitrator. The network's 2 outputs ``m`` in [0, 1]^2 go
  through a mapping function (paper eq. 7-9) onto the repertoire's behaviour space, and
  the nearest primitive runs; it needs the repertoire it was evolved with and a mapping.
* ``standard``: the standard-NEAT baseline. The network has one output per locomotion
  parameter, in [0, 1], mapped linearly onto the gene range [-1, 1]; no repertoire.

Files keep the name (``"kind": "evorbc"``). A record compares equal to its name and
prints as it, so code written against the names (a task of one's own, section 20) keeps
working.
"""

from __future__ import annotations

import reprlib
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True, eq=False)
class ControllerKind:
    """What differs between the controller kinds; one shared instance per kind."""

    name: str  # as files and the command line write it
    label: str  # in figures and reports
    noun: str  # what its file holds, in messages
    command: str  # the evorbc-evolve subcommand that evolves one
    # The network's outputs choose a repertoire primitive through a mapping (EvoRBC);
    # otherwise they are the genes themselves (standard NEAT).
    uses_repertoire: bool

    def n_outputs(self, n_parameters: int) -> int:
        """Network outputs: 2 mapping values, or one per locomotion parameter."""
        return 2 if self.uses_repertoire else n_parameters

    def __str__(self) -> str:
        return self.name

    def __eq__(self, other: object) -> bool:
        if isinstance(other, str):
            return other == self.name
        return other is self

    def __hash__(self) -> int:
        return hash(self.name)

    def __reduce__(self):
        # Pickled (to worker processes) and deep-copied by name: one instance per kind.
        return controller_kind, (self.name,)


EVORBC = ControllerKind("evorbc", "EvoRBC", "arbitrator", "arbitrator", uses_repertoire=True)
STANDARD = ControllerKind(
    "standard", "standard NEAT", "standard-NEAT controller", "standard", uses_repertoire=False
)
#: Every kind by its name, in the order messages list them.
KINDS: dict[str, ControllerKind] = {k.name: k for k in (EVORBC, STANDARD)}


def controller_kind(
    value: Any, source: str = "kind", error: type[Exception] = ValueError
) -> ControllerKind:
    """The record of kind ``value`` (a name, or a record, returned as it is).

    Raises:
        error: ``<source>: kind must be one of evorbc, standard, got <value>``.
    """
    if isinstance(value, ControllerKind):
        return value
    kind = KINDS.get(value) if isinstance(value, str) else None
    if kind is None:
        raise error(f"{source}: kind must be one of {', '.join(KINDS)}, got {reprlib.repr(value)}")
    return kind


def direct_genes(outputs: np.ndarray) -> np.ndarray | None:
    """A standard controller's genes ``(d,)`` in [-1, 1] from its outputs ``(d,)``.

    The sigmoid outputs in [0, 1] map linearly onto the gene range. None when an output
    is not finite: there are no parameters to run and the robot stops for the cycle (as
    an EvoRBC arbitrator's :data:`~evorbc_ros.mapping.NO_PRIMITIVE`).
    """
    if not np.all(np.isfinite(outputs)):
        return None
    return 2.0 * np.clip(outputs, 0.0, 1.0) - 1.0
