"""Arbitrator files and the onboard controller they describe.

An arbitrator file is JSON, versioned, never pickled::

    {"format": "evorbc-arbitrator", "version": 1,
     "kind": "evorbc",                 # or "standard": the network drives the parameters
     "robot": "4ws-5",
     "network": {...},                 # evorbc_ros.network.NetworkSpec.to_dict()
     "inputs": ["range_000", ...],     # one name per network input
     "sensors": {...},                 # evorbc_ros.sensors.SensorLayout.to_dict()
     "sensors_fingerprint": "...",
     "mapping": "polar",               # evorbc only
     "repertoire": {"fingerprint": "...", "robot": "4ws-5", "count": 262, "file": "..."},
     "parameters": [...],              # standard only: the outputs' parameter specs
     "control_period": 0.1,
     "evolution": {...}}               # how it was made: seed, generations, fitness, ...

An EvoRBC arbitrator only makes sense with the repertoire it was evolved with; loading it
with another repertoire (different fingerprint) or another sensor layout is an error unless
the caller explicitly allows the mismatch, which then comes back as a warning.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.json_files import load_json_file
from evorbc_ros.mapping import MAPPINGS, MappingFunction, PrimitiveLookup
from evorbc_ros.network import NetworkError, NetworkSpec
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.primitive import ParameterSpec
from evorbc_ros.sensors import SensorLayout

FORMAT = "evorbc-arbitrator"
VERSION = 1
KINDS = ("evorbc", "standard")


class ArbitratorError(ValueError):
    """An arbitrator file is invalid or does not fit the repertoire or sensors given."""


@dataclass
class ArbitratorFile:
    """The contents of an arbitrator file."""

    kind: str
    robot: str
    network: NetworkSpec
    sensors: SensorLayout
    mapping: str | None = None
    repertoire: dict[str, Any] | None = None
    parameters: tuple[ParameterSpec, ...] = ()
    control_period: float = 0.1
    evolution: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form written to files."""
        out = {
            "format": FORMAT,
            "version": VERSION,
            "kind": self.kind,
            "robot": self.robot,
            "network": self.network.to_dict(),
            "inputs": self.sensors.input_names(),
            "sensors": self.sensors.to_dict(),
            "sensors_fingerprint": self.sensors.fingerprint(),
            "control_period": self.control_period,
            "evolution": self.evolution,
        }
        if self.kind == "evorbc":
            out["mapping"] = self.mapping
            out["repertoire"] = self.repertoire
        else:
            out["parameters"] = [p.as_dict() for p in self.parameters]
        return out

    def save(self, path: str | os.PathLike) -> None:
        """Write the file atomically."""
        atomic_write_text(path, json.dumps(self.to_dict(), indent=1) + "\n")

    @classmethod
    def load(cls, path: str | os.PathLike) -> ArbitratorFile:
        """Load and validate an arbitrator file.

        Raises:
            ArbitratorError: one line naming the file and the problem.
        """
        data = load_json_file(path, "arbitrator", ArbitratorError)
        return cls.from_dict(data, str(path))

    @classmethod
    def from_dict(cls, data: Any, source: str = "arbitrator") -> ArbitratorFile:
        """Validate the plain-data form; raises :class:`ArbitratorError` naming ``source``."""
        if not isinstance(data, dict):
            raise ArbitratorError(f"{source}: expected a JSON object at the top level")
        if data.get("format") != FORMAT:
            raise ArbitratorError(
                f"{source}: not an arbitrator file (format is "
                f"{data.get('format')!r}, expected {FORMAT!r})"
            )
        if data.get("version") != VERSION:
            raise ArbitratorError(
                f"{source}: arbitrator format version "
                f"{data.get('version')!r} is not supported (this evorbc "
                f"reads version {VERSION})"
            )
        kind = data.get("kind")
        if kind not in KINDS:
            raise ArbitratorError(f"{source}: kind must be one of {', '.join(KINDS)}, got {kind!r}")
        for key in ("robot", "network", "sensors"):
            if key not in data:
                raise ArbitratorError(f"{source}: missing key {key}")
        try:
            network = NetworkSpec.from_dict(data["network"])
        except NetworkError as e:
            raise ArbitratorError(f"{source}: network: {e}") from None
        except (TypeError, AttributeError):
            raise ArbitratorError(f"{source}: network is malformed") from None
        try:
            sensors = SensorLayout.from_dict(data["sensors"], f"{source}: sensors")
        except ValueError as e:
            raise ArbitratorError(str(e)) from None
        if len(network.input_keys) != sensors.n_inputs:
            raise ArbitratorError(
                f"{source}: the network has {len(network.input_keys)} inputs "
                f"but the sensor layout gives {sensors.n_inputs}"
            )
        fp = data.get("sensors_fingerprint")
        if fp is not None and fp != sensors.fingerprint():
            raise ArbitratorError(
                f"{source}: sensors_fingerprint does not match the sensors "
                "section (the file was edited)"
            )
        out = cls(
            kind=kind,
            robot=str(data["robot"]),
            network=network,
            sensors=sensors,
            control_period=float(data.get("control_period", 0.1)),
            evolution=data.get("evolution", {}) or {},
        )
        if kind == "evorbc":
            if data.get("mapping") not in MAPPINGS:
                raise ArbitratorError(f"{source}: mapping must be one of {', '.join(MAPPINGS)}")
            rep = data.get("repertoire")
            if not isinstance(rep, dict) or not isinstance(rep.get("fingerprint"), str):
                raise ArbitratorError(f"{source}: repertoire.fingerprint is missing")
            if len(network.output_keys) != 2:
                raise ArbitratorError(
                    f"{source}: an EvoRBC network needs 2 outputs, it has "
                    f"{len(network.output_keys)}"
                )
            out.mapping = data["mapping"]
            out.repertoire = rep
        else:
            try:
                out.parameters = tuple(
                    ParameterSpec(str(p["name"]), str(p["unit"]), float(p["low"]), float(p["high"]))
                    for p in data["parameters"]
                )
            except (KeyError, TypeError, ValueError):
                raise ArbitratorError(
                    f"{source}: parameters must list name, unit, low and high for each output"
                ) from None
            if len(out.parameters) != len(network.output_keys):
                raise ArbitratorError(
                    f"{source}: {len(network.output_keys)} outputs but "
                    f"{len(out.parameters)} parameters"
                )
        return out

    def check_repertoire(
        self, repertoire: Repertoire, source: str, allow_mismatch: bool = False
    ) -> list[str]:
        """Check that ``repertoire`` is the one this arbitrator was evolved with.

        Returns:
            Warnings (only when ``allow_mismatch`` let a mismatch through).

        Raises:
            ArbitratorError: a mismatch, unless ``allow_mismatch``.
        """
        if self.kind != "evorbc":
            return []
        problems = []
        if repertoire.robot != self.robot:
            problems.append(f"it is for robot {repertoire.robot}, the arbitrator for {self.robot}")
        expected = (self.repertoire or {}).get("fingerprint")
        got = repertoire.fingerprint()
        if expected != got:
            problems.append(
                f"its fingerprint is {got[:12]}, the arbitrator was evolved with "
                f"{str(expected)[:12]}"
            )
        if not problems:
            return []
        message = f"repertoire {source} does not match the arbitrator: {'; '.join(problems)}"
        if not allow_mismatch:
            raise ArbitratorError(message + " (allow the mismatch explicitly to use it anyway)")
        return [message]

    def check_sensors(
        self, layout: SensorLayout, source: str, allow_mismatch: bool = False
    ) -> list[str]:
        """Check that the onboard sensor layout is the one the arbitrator expects."""
        if layout.fingerprint() == self.sensors.fingerprint():
            return []
        message = (
            f"sensor layout {source} differs from the arbitrator's "
            f"({layout.input_names()} vs {self.sensors.input_names()})"
        )
        if not allow_mismatch:
            raise ArbitratorError(message + " (allow the mismatch explicitly to use it anyway)")
        return [message]


class Arbitrator:
    """The onboard EvoRBC controller: inputs -> network -> mapping -> primitive."""

    def __init__(self, spec: ArbitratorFile, repertoire: Repertoire, grid_cells: int = 256):
        if spec.kind != "evorbc":
            raise ArbitratorError(
                "a standard-NEAT controller has no primitives; use DirectController"
            )
        self.spec = spec
        self.repertoire = repertoire
        self.network = spec.network.compile()
        self.mapping = MappingFunction.for_behaviours(spec.mapping, repertoire.behaviour)
        self.lookup = PrimitiveLookup.build(repertoire.behaviour, self.mapping.domain(), grid_cells)

    def outputs(self, inputs) -> np.ndarray:
        """The network's mapping values ``m`` in [0, 1]^2 for sensor ``inputs``."""
        return self.network.activate(inputs)

    def choose(self, inputs) -> tuple[int, np.ndarray]:
        """The primitive to run next and the mapping values that chose it."""
        m = self.outputs(inputs)
        x, y = self.mapping.point(m[0], m[1])
        return self.lookup.nearest(x, y), m


class DirectController:
    """A standard-NEAT controller: the network outputs the locomotion genes directly."""

    def __init__(self, spec: ArbitratorFile):
        if spec.kind != "standard":
            raise ArbitratorError("an EvoRBC arbitrator needs its repertoire; use Arbitrator")
        self.spec = spec
        self.network = spec.network.compile()

    def genes(self, inputs) -> np.ndarray:
        """Genes in [-1, 1] (one per locomotion parameter): sigmoid outputs mapped linearly."""
        return 2.0 * np.clip(self.network.activate(inputs), 0.0, 1.0) - 1.0
