"""Arbitrator files and the onboard controller they describe.

An arbitrator file is JSON, versioned, never pickled::

    {"format": "evorbc-arbitrator", "version": 1,
     "kind": "evorbc",                 # or "standard": the network drives the parameters
     "robot": "4ws-5",
     "network": {...},                 # evorbc_ros.network.NetworkSpec.to_dict(); with
                                       # "recurrent": true if it keeps state
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
the caller explicitly allows the mismatch, which then comes back as a warning. A repertoire
for another robot is always an error: its primitives cannot drive this robot at all.
"""

from __future__ import annotations

import json
import math
import os
import reprlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.controller_kinds import ControllerKind, controller_kind, direct_genes
from evorbc_ros.input_files import ARBITRATOR_LIMIT
from evorbc_ros.json_files import load_json_file
from evorbc_ros.mapping import MAPPINGS, MappingFunction, PrimitiveLookup, choose_primitive
from evorbc_ros.network import NetworkError, NetworkSpec
from evorbc_ros.repertoire import Repertoire, robot_problem
from evorbc_ros.repertoire_checks import version_problem
from evorbc_ros.robots.primitive import ParameterSpec
from evorbc_ros.robots.registry import lookup
from evorbc_ros.sensors import SensorLayout

FORMAT = "evorbc-arbitrator"
VERSION = 1


class ArbitratorError(ValueError):
    """An arbitrator file is invalid or does not fit the repertoire or sensors given."""


@dataclass
class ArbitratorFile:
    """The contents of an arbitrator file.

    ``kind`` may be given by name; it is kept as its record
    (:mod:`evorbc_ros.controller_kinds`).
    """

    kind: ControllerKind
    robot: str
    network: NetworkSpec
    sensors: SensorLayout
    mapping: str | None = None
    repertoire: dict[str, Any] | None = None
    parameters: tuple[ParameterSpec, ...] = ()
    control_period: float = 0.1
    evolution: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.kind = controller_kind(self.kind, "arbitrator", ArbitratorError)

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form written to files."""
        out = {
            "format": FORMAT,
            "version": VERSION,
            "kind": self.kind.name,
            "robot": self.robot,
            "network": self.network.to_dict(),
            "inputs": self.sensors.input_names(),
            "sensors": self.sensors.to_dict(),
            "sensors_fingerprint": self.sensors.fingerprint(),
            "control_period": self.control_period,
            "evolution": self.evolution,
        }
        if self.kind.uses_repertoire:
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
        data = load_json_file(path, "arbitrator", ArbitratorError, ARBITRATOR_LIMIT)
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
        problem = version_problem(data.get("version"), "arbitrator", VERSION)
        if problem:
            raise ArbitratorError(f"{source}: {problem}")
        kind = controller_kind(data.get("kind"), source, ArbitratorError)
        for key in ("robot", "network", "sensors"):
            if key not in data:
                raise ArbitratorError(f"{source}: missing key {key}")
        problem = robot_problem(data["robot"])
        if problem:
            raise ArbitratorError(f"{source}: {problem}")
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
        _check_sensor_records(data, sensors, source)
        out = cls(
            kind=kind,
            robot=data["robot"],
            network=network,
            sensors=sensors,
            control_period=_control_period(data, source),
            evolution=_evolution(data, source),
        )
        if kind.uses_repertoire:
            if data.get("mapping") not in MAPPINGS:
                raise ArbitratorError(f"{source}: mapping must be one of {', '.join(MAPPINGS)}")
            rep = data.get("repertoire")
            if not isinstance(rep, dict) or not isinstance(rep.get("fingerprint"), str):
                raise ArbitratorError(f"{source}: repertoire.fingerprint is missing")
            named = rep.get("file")
            # Readers look for the file next to the arbitrator; a path could lead anywhere.
            if named is not None and not _plain_file_name(named):
                raise ArbitratorError(
                    f"{source}: repertoire.file must be a plain file name (no folder), "
                    f"got {reprlib.repr(named)}"
                )
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
            problem = robot_problem(out.robot, len(out.parameters))
            if problem:
                raise ArbitratorError(f"{source}: {problem}")
        return out

    def check_repertoire(
        self, repertoire: Repertoire, source: str, allow_mismatch: bool = False, waiver: str = ""
    ) -> list[str]:
        """Check that ``repertoire`` is the one this arbitrator was evolved with.

        Args:
            waiver: how the caller's user allows a mismatch (``"--allow-mismatch"``), named
                in the error; empty when the caller offers no way.

        Returns:
            Warnings (only when ``allow_mismatch`` let another fingerprint through).

        Raises:
            ArbitratorError: a repertoire for another robot or gene count (always), or
                another fingerprint unless ``allow_mismatch``.
        """
        if not self.kind.uses_repertoire:
            return []
        head = f"repertoire {source} does not match the arbitrator"
        if repertoire.robot != self.robot:
            raise ArbitratorError(
                f"{head}: it is for robot {repertoire.robot}, the arbitrator for {self.robot}"
            )
        expected_parameters = lookup(self.robot).n_parameters
        if repertoire.n_parameters != expected_parameters:  # made in memory
            raise ArbitratorError(
                f"{head}: its primitives have {repertoire.n_parameters} parameters, "
                f"robot {self.robot} has {expected_parameters}"
            )
        expected = (self.repertoire or {}).get("fingerprint")
        got = repertoire.fingerprint()
        if expected == got:
            return []
        message = (
            f"{head}: its fingerprint is {got[:12]}, the arbitrator was evolved with "
            f"{str(expected)[:12]}"
        )
        return _mismatch(message, allow_mismatch, waiver)

    def check_sensors(
        self, layout: SensorLayout, source: str, allow_mismatch: bool = False, waiver: str = ""
    ) -> list[str]:
        """Check that the onboard sensor layout is the one the arbitrator expects.

        Returns and raises as :meth:`check_repertoire` does for another fingerprint.
        """
        if layout.fingerprint() == self.sensors.fingerprint():
            return []
        # The first setting that differs, not both layouts: a short line whatever they hold.
        what = layout.difference(self.sensors, "the arbitrator")
        message = f"sensor layout {source} differs from the arbitrator's ({what})"
        return _mismatch(message, allow_mismatch, waiver)


def _mismatch(message: str, allow: bool, waiver: str) -> list[str]:
    """The warning for a mismatch the caller allowed; else raise, naming ``waiver`` if any."""
    if allow:
        return [message]
    hint = f" (pass {waiver} to use it anyway)" if waiver else ""
    raise ArbitratorError(message + hint)


def _check_sensor_records(data: dict, sensors: SensorLayout, source: str) -> None:
    """The fingerprint and input names recorded next to the sensors section must match it.

    Both are required: the fingerprint is what reveals a hand-edited sensors section.
    """
    fp = data.get("sensors_fingerprint")
    if fp is None:
        raise ArbitratorError(f"{source}: missing key sensors_fingerprint")
    if fp != sensors.fingerprint():
        raise ArbitratorError(
            f"{source}: sensors_fingerprint does not match the sensors "
            "section (the file was edited)"
        )
    names = data.get("inputs")
    expected = sensors.input_names()
    if not isinstance(names, list):
        raise ArbitratorError(f"{source}: inputs must list the {len(expected)} input names")
    if names != expected:
        k = next((k for k, (a, b) in enumerate(zip(names, expected, strict=False)) if a != b), None)
        detail = (
            f"inputs[{k}] is {reprlib.repr(names[k])}, the sensor layout's is {expected[k]!r}"
            if k is not None
            else f"{len(names)} input names, the sensor layout gives {len(expected)}"
        )
        raise ArbitratorError(f"{source}: inputs do not match the sensors section ({detail})")


def _plain_file_name(name: Any) -> bool:
    """A file name without any folder part (``r.json``, not ``../r.json`` or ``..``)."""
    return isinstance(name, str) and name not in ("", ".", "..") and Path(name).name == name


def _control_period(data: dict, source: str) -> float:
    """``control_period`` (s): a finite number > 0; 0.1 s when the file has none."""
    value = data.get("control_period", 0.1)
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float))
        or not (math.isfinite(value) and value > 0)
    ):
        raise ArbitratorError(
            f"{source}: control_period must be a number of seconds > 0, got {reprlib.repr(value)}"
        )
    return float(value)


def _evolution(data: dict, source: str) -> dict:
    """The ``evolution`` record: a mapping; replay rebuilds its ``task`` settings."""
    evolution = data.get("evolution", {})
    if evolution is None:
        return {}
    if not isinstance(evolution, dict):
        raise ArbitratorError(
            f"{source}: evolution must be a mapping, got {reprlib.repr(evolution)}"
        )
    for key in ("task", "simulation"):
        if key in evolution and not isinstance(evolution[key], (dict, type(None))):
            raise ArbitratorError(
                f"{source}: evolution.{key} must be a mapping, got {reprlib.repr(evolution[key])}"
            )
    return evolution


class Arbitrator:
    """The onboard EvoRBC controller: inputs -> network -> mapping -> primitive."""

    def __init__(self, spec: ArbitratorFile, repertoire: Repertoire, grid_cells: int = 256):
        if not spec.kind.uses_repertoire:
            raise ArbitratorError(
                "a standard-NEAT controller has no primitives; use DirectController"
            )
        self.spec = spec
        self.repertoire = repertoire
        self.network = spec.network.compile()
        self.mapping = MappingFunction.for_behaviours(spec.mapping, repertoire.behaviour)
        self.lookup = PrimitiveLookup.build(repertoire.behaviour, self.mapping.domain(), grid_cells)

    def reset(self) -> None:
        """Start an episode: a recurrent network's state back to 0 (no-op if feed-forward)."""
        self.network.reset()

    def outputs(self, inputs) -> np.ndarray:
        """The network's mapping values ``m`` in [0, 1]^2 for sensor ``inputs``.

        A recurrent network steps once per call (one control cycle).
        """
        return self.network.activate(inputs)

    def choose(self, inputs) -> tuple[int, np.ndarray]:
        """The primitive to run next and the mapping values that chose it.

        The index is :data:`~evorbc_ros.mapping.NO_PRIMITIVE` when the outputs (or the
        point they map to) are not finite: the robot must stop for the cycle.
        """
        m = self.outputs(inputs)
        return choose_primitive(self.mapping, self.lookup, m[0], m[1])[0], m

    def choose_point(self, inputs) -> tuple[int, np.ndarray, float, float]:
        """:meth:`choose` and the behaviour-space point ``(x, y)`` (m; NaN if none)."""
        m = self.outputs(inputs)
        index, x, y = choose_primitive(self.mapping, self.lookup, m[0], m[1])
        return index, m, x, y


class DirectController:
    """A standard-NEAT controller: the network outputs the locomotion genes directly."""

    def __init__(self, spec: ArbitratorFile):
        if spec.kind.uses_repertoire:
            raise ArbitratorError("an EvoRBC arbitrator needs its repertoire; use Arbitrator")
        self.spec = spec
        self.network = spec.network.compile()

    def reset(self) -> None:
        """Start an episode: a recurrent network's state back to 0 (no-op if feed-forward)."""
        self.network.reset()

    def genes(self, inputs) -> np.ndarray | None:
        """Genes in [-1, 1] (one per locomotion parameter): sigmoid outputs mapped linearly.

        None when an output is not finite: no parameters to run, the robot must stop for
        the cycle (as an EvoRBC arbitrator's :data:`~evorbc_ros.mapping.NO_PRIMITIVE`).
        """
        return direct_genes(self.network.activate(inputs))
