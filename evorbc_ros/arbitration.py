"""The arbitrator node's pure part: load the controller, gather inputs, choose.

Inputs come in groups (rangefinder readings, goal readings) on separate topics. A choice
is made once every group has delivered a new message since the previous choice, so in a
lockstep simulation each choice uses the readings of one instant.
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.arbitrator import Arbitrator, ArbitratorFile, DirectController
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.laser import InputError
from evorbc_ros.repertoire import Repertoire


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
        if self.spec.kind == "evorbc":
            self.repertoire_path = repertoire_path or str(default_repertoire(self.spec.robot))
            self.repertoire = Repertoire.load(self.repertoire_path)
            self.warnings = self.spec.check_repertoire(
                self.repertoire, self.repertoire_path, allow_mismatch
            )
            self.arbitrator = Arbitrator(self.spec, self.repertoire)
        else:
            self.repertoire_path = ""
            self.direct = DirectController(self.spec)

    @property
    def parameter_names(self) -> list[str]:
        """Names of the genes published for the executor."""
        if self.repertoire is not None:
            return [p.name for p in self.repertoire.parameters]
        return [p.name for p in self.spec.parameters]

    def step(self, inputs: np.ndarray) -> tuple[np.ndarray, list[float]]:
        """Genes to run and a diagnostic row ``[m1, m2, x, y, primitive]`` (EvoRBC).

        Raises:
            InputError: the wrong number of inputs.
        """
        if inputs.shape != (self.spec.sensors.n_inputs,):
            raise InputError(f"expected {self.spec.sensors.n_inputs} inputs, got {inputs.size}")
        if self.repertoire is None:
            return self.direct.genes(inputs), []
        index, m = self.arbitrator.choose(inputs)
        x, y = self.arbitrator.mapping.point(m[0], m[1])
        return self.repertoire.genes[index], [float(m[0]), float(m[1]), x, y, float(index)]
