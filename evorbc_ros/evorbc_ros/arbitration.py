"""The arbitrator node's pure part: load the controller, gather inputs, choose.

Inputs come in groups (rangefinder readings, goal readings) on separate topics. A choice
is made once every group has delivered a new message since the previous choice, so in a
lockstep simulation each choice uses the readings of one instant.

An EvoRBC controller may adapt (off unless :meth:`Controller.enable_adaptation` is
called): it is then fed odometry poses (:meth:`Controller.put_pose`) and matches the
network's choice against corrected outcomes (docs/design.md section 24).
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.adaptation import (
    AdaptationSettings,
    OnlineAdaptation,
    adapted_choice,
    outcome_table,
    settings_for,
)
from evorbc_ros.adaptation.settled import SettledError, load_settled, settled_path
from evorbc_ros.arbitrator import Arbitrator, ArbitratorFile, DirectController
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.laser import InputError
from evorbc_ros.mapping import NO_PRIMITIVE
from evorbc_ros.repertoire import Repertoire

#: The label of the empty primitive an arbitrator sends when it is deactivated (stop the
#: robot), which tells it from a cycle's "no primitive" (docs/design.md section 9).
DEACTIVATED = "deactivated"


def robot_family(robot: str) -> str:
    """The registry's family of ``robot`` ("" for a robot it does not know)."""
    from evorbc_ros.robots import registry

    return registry.lookup(robot).family if registry.known(robot) else ""


class InputGroups:
    """The latest values of each input group and whether all are new."""

    def __init__(self, sizes: dict[str, int]):
        self.sizes = sizes
        self.values = {name: None for name in sizes}
        self.fresh = dict.fromkeys(sizes, False)

    def put(self, name: str, values: np.ndarray) -> bool:
        """Store a group's new values; True when every group is new."""
        self.values[name] = values
        self.fresh[name] = True
        return all(self.fresh.values())

    def take(self) -> np.ndarray:
        """All inputs in group order; marks every group as used."""
        self.fresh = dict.fromkeys(self.fresh, False)
        return np.concatenate([self.values[name] for name in self.sizes])


class Controller:
    """An EvoRBC arbitrator with its repertoire, or a standard-NEAT controller."""

    def __init__(
        self, arbitrator_path: str = "", repertoire_path: str = "", allow_mismatch: bool = False
    ):
        self.arbitrator_path = arbitrator_path or str(default_arbitrator())
        self.spec = ArbitratorFile.load(self.arbitrator_path)
        self.warnings: list[str] = []
        self.repertoire = None
        if self.spec.kind.uses_repertoire:
            self.repertoire_path = repertoire_path or str(default_repertoire(self.spec.robot))
            self.repertoire = Repertoire.load(self.repertoire_path)
            self.warnings = self.spec.check_repertoire(
                self.repertoire, self.repertoire_path, allow_mismatch
            )
            self.arbitrator = Arbitrator(self.spec, self.repertoire)
        else:
            self.repertoire_path = ""
            self.direct = DirectController(self.spec)
        #: The online outcome model, or None: adaptation is off (the default).
        self.adaptation: OnlineAdaptation | None = None
        #: Primitive chosen by the last step (-1: none yet, or none that cycle).
        self.last_index = -1

    @property
    def recurrent(self) -> bool:
        """Whether the network keeps state from one choice to the next."""
        return self.spec.network.recurrent

    def reset(self) -> None:
        """Start an episode: a recurrent network's state back to 0 (no-op if feed-forward).

        What adaptation learned is kept (the robot is the same robot for a new goal);
        :meth:`reset_adaptation` forgets it.
        """
        (self.arbitrator if self.repertoire is not None else self.direct).reset()

    def enable_adaptation(
        self, settings: AdaptationSettings | None = None, expected: np.ndarray | None = None
    ) -> None:
        """Start adapting, from the prior (docs/design.md section 24).

        Args:
            settings: the model's; default the robot family's
                (:func:`~evorbc_ros.adaptation.settings_for`: legged robots observe
                whole 0.5 s executions).
            expected: ``(n, 3)`` what each primitive's settled cycles should read on the
                robot the repertoire was made on, over its evaluation time ``(dx m, dy m,
                dheading rad)``; default the recorded outcomes.

        Raises:
            ValueError: a standard-NEAT controller (it has no primitives to correct).
        """
        if self.repertoire is None:
            raise ValueError("adaptation needs an EvoRBC controller (with a repertoire)")
        rep = self.repertoire
        if settings is None:
            settings = settings_for(robot_family(self.spec.robot))
        recorded = outcome_table(rep.behaviour, rep.heading)
        self.adaptation = OnlineAdaptation(recorded, rep.eval_time, settings, expected)

    def settled_outcomes(self, path: str = "") -> np.ndarray:
        """``(n, 3)`` the repertoire's settled outcomes, read from their file.

        What each primitive does once its actuators hold its command ``(dx m, dy m,
        dheading rad)`` over the repertoire's evaluation time, for
        :meth:`enable_adaptation`'s ``expected`` (docs/design/adaptation.md, "What an
        observation is compared with"). ``path``: the file; "" the one beside the
        repertoire (``NAME.settled.json``, written by ``evorbc-evolve settled``).

        Raises:
            SettledError: a standard-NEAT controller, or a file that is missing, bad or
                made for another repertoire (one line naming it).
        """
        if self.repertoire is None:
            raise SettledError("settled outcomes need an EvoRBC controller (with a repertoire)")
        return load_settled(path or settled_path(self.repertoire_path), self.repertoire)

    def disable_adaptation(self) -> None:
        """Stop adapting and forget what was learned: choices are the evolved ones again."""
        self.adaptation = None

    def reset_adaptation(self) -> None:
        """Forget every observation: the corrected outcomes are the recorded ones again."""
        if self.adaptation is not None:
            self.adaptation.reset()

    def put_pose(self, stamp_ns: int, x: float, y: float, yaw: float) -> None:
        """The newest odometry pose: ``(x m, y m)`` and ``yaw`` (rad) in its fixed frame.

        Ignored while adaptation is off. The next :meth:`step` attributes the motion since
        the last step to the primitive chosen then.
        """
        if self.adaptation is not None:
            self.adaptation.put_pose(stamp_ns, x, y, yaw)

    def adaptation_state(self) -> dict[str, float | int]:
        """What adaptation knows, for diagnostics ({} while off).

        ``observations`` (taken since the reset), ``primitives observed`` (in the model),
        ``mean correction m`` and ``mean heading correction rad`` (over every primitive),
        ``uncertainty`` of the last chosen primitive (posterior variance over the prior's:
        1 unknown, 0 certain).
        """
        a = self.adaptation
        if a is None:
            return {}
        move, turn = a.model.mean_correction()
        return {
            "observations": a.model.observations,
            "primitives observed": a.model.used,
            "mean correction m": move,
            "mean heading correction rad": turn,
            "uncertainty": a.model.uncertainty(self.last_index),
        }

    @property
    def parameter_names(self) -> list[str]:
        """Names of the genes published for the executor."""
        if self.repertoire is not None:
            return [p.name for p in self.repertoire.parameters]
        return [p.name for p in self.spec.parameters]

    def step(self, inputs: np.ndarray) -> tuple[np.ndarray, list[float]]:
        """Genes to run and a diagnostic row ``[m1, m2, x, y, primitive]`` (EvoRBC).

        One call is one control cycle: a recurrent network steps once.

        When the network's outputs are not finite there is no primitive to run: the genes
        are empty (``(0,)``, published as an empty message that stops the robot at once)
        and the row holds the outputs, NaN for the point and ``NO_PRIMITIVE`` (-1).

        Raises:
            InputError: the wrong number of inputs.
        """
        if inputs.shape != (self.spec.sensors.n_inputs,):
            raise InputError(f"expected {self.spec.sensors.n_inputs} inputs, got {inputs.size}")
        if self.repertoire is None:
            genes = self.direct.genes(inputs)
            return (np.empty(0) if genes is None else genes), []
        index, m, x, y = self.arbitrator.choose_point(inputs)
        if self.adaptation is not None:
            index = adapted_choice(self.adaptation, self.arbitrator.lookup, index, x, y)
        self.last_index = index
        row = [float(m[0]), float(m[1]), x, y, float(index)]
        if index == NO_PRIMITIVE:
            return np.empty(0), row
        return self.repertoire.genes[index], row

    @staticmethod
    def no_primitive_reason(inputs: np.ndarray, genes: np.ndarray, row: list[float]) -> str:
        """Why :meth:`step` chose nothing, for the log ("" when it chose a primitive)."""
        if len(genes):
            return ""
        what = f"outputs ({row[0]!r}, {row[1]!r})" if row else "outputs"
        return (
            f"the network's {what} are not finite or map to no finite point, for inputs "
            f"{np.round(inputs, 3).tolist()}: no primitive, the robot stops"
        )
