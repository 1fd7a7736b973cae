"""The task protocol: what arbitrator evolution needs from a task (docs/design.md section 20).

Arbitrator evolution (:func:`offline_evolution.arbitrator.evolve.evolve`) runs NEAT on any
object that implements :class:`ArbitratorTask`. Both maze tasks do: the compiled 4WS
:class:`~offline_evolution.maze_task.task.MazeTask` and the PyBullet
:class:`~offline_evolution.maze_task.hexapod_task.HexapodMazeTask`; a researcher's own task
(another simulator, another goal) does the same to evolve an arbitrator for it.

The evolution only passes things through: it asks the task for a controller once, for
start rows every generation, and for one :class:`EpisodeResult` per network and start. So
a task decides what a start row holds (the maze tasks: ``(maze, x m, y m, heading rad)``),
what its controller object is, and how an episode runs; the evolution reads only the
results' ``fitness`` and ``reached``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple, Protocol, runtime_checkable

import numpy as np

from evorbc_ros.controller_kinds import KINDS as CONTROLLER_KINDS
from evorbc_ros.controller_kinds import ControllerKind
from evorbc_ros.network import NetworkSpec
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.primitive import ParameterSpec
from evorbc_ros.sensors import SensorLayout

#: The controller kinds a task builds, by the name an arbitrator file's ``kind`` gives.
KINDS = CONTROLLER_KINDS


class EpisodeResult(NamedTuple):
    """Per-episode outcome (arrays of length E) and, if recorded, traces.

    Traces cover every cycle of the task's episode length; cycles an episode did not run
    (it ended early) hold NaN poses and outputs and the choice ``-2``.
    """

    reached: np.ndarray  # (E,) bool, the target was reached
    cycles: np.ndarray  # (E,) int, control cycles run (to the target, or all)
    final_distance: np.ndarray  # (E,) m, to the target at the end
    initial_distance: np.ndarray  # (E,) m, to the target at the start
    fitness: np.ndarray  # (E,) the task's fitness (maze tasks: eq. 5), higher is better
    pose: np.ndarray | None = None  # (E, n_cycles + 1, 3) x m, y m, heading rad per cycle
    choice: np.ndarray | None = None  # (E, n_cycles) primitive index (-1: none or standard)
    outputs: np.ndarray | None = None  # (E, n_cycles, n_outputs) network outputs
    fell: np.ndarray | None = None  # (E,) bool, the robot fell over (legged robots only)


@runtime_checkable
class ArbitratorTask(Protocol):
    """A task arbitrators are evolved on: sensors, controllers, starts and episodes.

    Attributes:
        layout: the arbitrator's inputs, in order (``layout.n_inputs`` network inputs);
            the arbitrator file records it and the onboard nodes rebuild the inputs
            from it.
        dt: s, the control period: the arbitrator chooses once per period.
        parameter_specs: the robot's locomotion parameters, one per gene; a standard
            controller's network has one output per parameter.

    """

    layout: SensorLayout
    dt: float

    @property
    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """Names, units and ranges of the robot's locomotion parameters."""
        ...

    def controller(
        self,
        kind: ControllerKind | str,
        repertoire: Repertoire | None = None,
        mapping: str | None = None,
    ) -> Any:
        """How network outputs become locomotion, for :meth:`evaluate`.

        Args:
            kind: the record (:mod:`evorbc_ros.controller_kinds`) or its name, which
                compares equal to it. ``"evorbc"``: the network's 2 outputs in [0, 1] go
                through the mapping function named ``mapping`` (``polar`` or
                ``cartesian``, paper eq. 7-9) onto ``repertoire``'s behaviour space, and
                the nearest primitive runs;
                ``"standard"``: the network's outputs (one per parameter, [0, 1]) are the
                genes, mapped onto [-1, 1].

        Returns:
            Any object :meth:`evaluate` takes; built once per run.

        """
        ...

    def sample_starts(self, rng: np.random.Generator) -> np.ndarray:
        """``(S, k)`` start rows for one generation, drawn only from ``rng``.

        Every genome of a generation runs from the same rows; the rows' columns are the
        task's own (the maze tasks: ``(maze, x m, y m, heading rad)``).
        """
        ...

    def nominal_starts(self) -> np.ndarray:
        """``(N, k)`` start rows that draw no random numbers (where demos start a robot).

        Rows like :meth:`sample_starts`' rows; the post-evaluation puts them first and
        the ``nominal_then_mean`` rule prefers networks that reach the target from all.
        """
        ...

    def evaluate(
        self,
        networks: Sequence[NetworkSpec],
        controller: Any,
        starts: np.ndarray,
        record: bool = False,
    ) -> EpisodeResult:
        """Run every network from every start row; E = ``len(networks) * len(starts)``.

        Episode ``i * len(starts) + j`` is network ``i`` from start ``j``. Episodes must
        not depend on one another or on the order they run in: the result of a run then
        does not depend on threads or worker processes. With ``record`` the result
        carries the traces (replays).
        """
        ...

    def describe(self) -> dict | None:
        """The simulated robot's design (JSON-safe), or None when there is nothing to check.

        Checkpoints and arbitrator files record it; a repertoire or checkpoint made for
        another design (``algorithm.simulation``) is refused.
        """
        ...

    def close(self) -> None:
        """Release the task's resources (worker processes); the task is not used again."""
        ...


__all__ = ["KINDS", "ArbitratorTask", "EpisodeResult"]
