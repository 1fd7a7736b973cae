"""Perturbed worlds: seeded per-episode randomisation of the robot, the room and the sensors.

A *perturbation set* (``config/perturbations/*.yaml``, docs/design.md section 21) gives a
``[low, high]`` range per quantity; each episode (each start row) draws one value of each,
uniformly, from a seeded generator. :class:`WorldDraw` holds the draws, one row per start,
and a maze task applies those its simulation has, which it lists in its
``perturbations_applied`` (:data:`KINEMATIC`, :data:`PYBULLET_LEGGED`; a plugin's task
lists its own):

* the 4WS robots' kinematic model (``sim_bridge/four_ws/motion.py``) has no friction, mass
  or servos; it takes the wheel speed gain, the latency, the rangefinder noise and
  dropouts and the start pose, inside the compiled kernel;
* the legged robots (PyBullet: the hexapod, the A1, any from a settings file,
  :mod:`sim_bridge.legged.perturbed`) take ground friction, body (root link) mass and
  payload, servo strength and speed, the latency, the laser's noise and dropouts and the
  start pose.

A set may also name one ``damage`` (:mod:`sim_bridge.damage`): a stuck, slow or slipping
4WS wheel, a lost, knee-locked or weak leg, a weak side. Its part and level are drawn per
row from the row's key, so a set without damage draws what it always drew.

The all-zero set (every factor 1, every noise 0, no damage) changes nothing, bit for bit;
so the same code runs with and without perturbations. Each start row gets its own noise key, so an
episode's noise does not depend on which other episodes run, or on threads or workers.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from evorbc_ros.config import ConfigError, config_dir, load_yaml_mapping
from sim_bridge.damage import DamageDraw, DamageSpec, number_pair

#: Each quantity: its identity value and the bounds a range must stay in.
QUANTITIES = {
    "friction": (1.0, 0.05, 5.0),
    "body_mass": (1.0, 0.2, 5.0),
    "payload": (0.0, 0.0, 2.0),
    "servo_strength": (1.0, 0.1, 2.0),
    "servo_speed": (1.0, 0.1, 2.0),
    "wheel_speed_gain": (1.0, 0.1, 2.0),
    "latency_cycles": (0.0, 0.0, 1.0),
    "range_noise": (0.0, 0.0, 1.0),
    "dropout": (0.0, 0.0, 1.0),
    "start_position": (0.0, 0.0, 1.0),
    "start_heading_deg": (0.0, 0.0, 180.0),
}
#: What the 4WS and differential-drive robots' kinematic model applies (no friction,
#: mass or servos).
KINEMATIC = (
    "wheel_speed_gain",
    "latency_cycles",
    "range_noise",
    "dropout",
    "start_position",
    "start_heading_deg",
)
#: What the legged robots' PyBullet simulation applies (no wheels).
PYBULLET_LEGGED = (
    "friction",
    "body_mass",
    "payload",
    "servo_strength",
    "servo_speed",
    "latency_cycles",
    "range_noise",
    "dropout",
    "start_position",
    "start_heading_deg",
)


@dataclass(frozen=True)
class PerturbationSet:
    """Ranges ``(low, high)`` per quantity (see ``config/perturbations/realistic.yaml``)."""

    name: str = "none"
    description: str = ""
    friction: tuple[float, float] = (1.0, 1.0)
    body_mass: tuple[float, float] = (1.0, 1.0)
    payload: tuple[float, float] = (0.0, 0.0)
    servo_strength: tuple[float, float] = (1.0, 1.0)
    servo_speed: tuple[float, float] = (1.0, 1.0)
    wheel_speed_gain: tuple[float, float] = (1.0, 1.0)
    latency_cycles: tuple[float, float] = (0.0, 0.0)
    range_noise: tuple[float, float] = (0.0, 0.0)
    dropout: tuple[float, float] = (0.0, 0.0)
    start_position: tuple[float, float] = (0.0, 0.0)
    start_heading_deg: tuple[float, float] = (0.0, 0.0)
    damage: DamageSpec | None = None

    @classmethod
    def from_dict(cls, data: dict, source: str) -> PerturbationSet:
        """A set from its YAML mapping; unnamed quantities stay unperturbed.

        Raises:
            ConfigError: naming ``source`` and the key: an unknown key, a range that is not
                two numbers with low <= high inside the quantity's bounds.
        """
        if not isinstance(data, dict):
            raise ConfigError(f"{source}: expected a mapping of perturbation ranges")
        known = {"name", "description", "damage", *QUANTITIES}
        for key in data:
            if key not in known:
                raise ConfigError(
                    f"{source}: unknown key {key!r}; known keys: {', '.join(sorted(known))}"
                )
        values = {}
        for key, (_, low, high) in QUANTITIES.items():
            if key not in data:
                continue
            v = data[key]
            if not number_pair(v):
                raise ConfigError(f"{source}: {key} must be [low, high], two numbers; got {v!r}")
            if not (low <= v[0] <= v[1] <= high):
                raise ConfigError(
                    f"{source}: {key} must be [low, high] with {low:g} <= low <= high <= "
                    f"{high:g}; got {list(v)}"
                )
            values[key] = (float(v[0]), float(v[1]))
        for key in ("name", "description"):
            if key in data and not isinstance(data[key], str):
                raise ConfigError(f"{source}: {key} must be text")
        if "damage" in data:
            values["damage"] = DamageSpec.from_dict(data["damage"], source)
        name = data.get("name", Path(source).stem)
        return cls(name=name, description=data.get("description", ""), **values)

    def ranges(self) -> dict[str, tuple[float, float]]:
        """The ranges by quantity."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name in QUANTITIES}

    def perturbed(self) -> tuple[str, ...]:
        """The quantities whose range is not just the identity value (damage aside)."""
        return tuple(k for k, (lo, hi) in self.ranges().items() if not lo == hi == QUANTITIES[k][0])

    def as_dict(self) -> dict:
        """Plain-data form (reports); ``damage`` only when the set has one."""
        out = {"name": self.name, **{k: list(v) for k, v in self.ranges().items()}}
        if self.damage:
            out["damage"] = self.damage.as_dict()
        return out

    def draw(self, rng: np.random.Generator, n: int) -> WorldDraw:
        """``n`` worlds, one per start row, from ``rng`` (always the same number of draws)."""
        cols = {}
        for key, (lo, hi) in self.ranges().items():
            u = rng.random(n)  # drawn for every quantity, so adding one shifts no other
            if key == "latency_cycles":
                cols[key] = np.floor(lo + u * (hi - lo + 1.0)).clip(lo, hi)
            else:
                cols[key] = lo + u * (hi - lo)
        angle = rng.uniform(-math.pi, math.pi, n)  # direction of the start offset
        turn = rng.uniform(-1.0, 1.0, n)  # share of the heading range, signed
        keys = rng.integers(0, 2**63 - 1, n, dtype=np.int64)
        damage = self.damage.draw(keys) if self.damage else None  # from the keys, not rng
        return WorldDraw(self.name, cols, angle, turn, keys, damage)


#: The identity: nothing perturbed.
NONE = PerturbationSet()


@dataclass(frozen=True)
class WorldDraw:
    """Per start row: the drawn value of each quantity and the row's noise key."""

    name: str
    values: dict  # quantity -> (S,) values
    start_angle: np.ndarray  # (S,) rad, direction of the start position offset
    start_turn: np.ndarray  # (S,) in [-1, 1], share of the heading offset
    keys: np.ndarray  # (S,) int64, seeds of each row's sensor noise
    damage: DamageDraw | None = None  # each row's damage, if the set has one

    def __len__(self) -> int:
        return len(self.keys)

    def row(self, k: int) -> dict:
        """Row ``k`` as plain floats (sent to PyBullet workers), with its key and damage."""
        out = {q: float(v[k]) for q, v in self.values.items()}
        out["key"] = int(self.keys[k])
        if self.damage is not None:
            out["damage"] = self.damage.row(k)
        return out

    def kernel_arrays(self, max_range: float) -> np.ndarray:
        """``(S, 7)`` for the 4WS kernel: gain, latency, noise sd, dropout, damage (3 columns).

        The columns: wheel speed gain, latency, reading noise sd, dropout probability, damage
        code (0 intact), damaged wheel, damage level. The reading noise is the range
        noise over ``max_range`` (m): rangefinder readings are in [0, 1]. Latency in whole
        cycles. Damage: :meth:`DamageDraw.wheel_arrays`.
        """
        v = self.values
        if self.damage is not None:
            wheel = self.damage.wheel_arrays()
        else:
            wheel = np.zeros((len(self.keys), 3))
        return np.ascontiguousarray(
            np.column_stack(
                [
                    v["wheel_speed_gain"],
                    v["latency_cycles"],
                    v["range_noise"] / max_range,
                    v["dropout"],
                    wheel,
                ]
            ),
            dtype=np.float64,
        )

    def shift_starts(self, starts: np.ndarray, mazes, robot_radius: float) -> np.ndarray:
        """Start rows ``(S, 4)`` moved by the drawn start errors.

        A row whose moved footprint would touch a wall keeps its position (the robot
        cannot start inside a wall) but still turns.
        """
        out = np.array(starts, dtype=np.float64, copy=True)
        dist = self.values["start_position"]
        turn = np.radians(self.values["start_heading_deg"]) * self.start_turn
        for k, row in enumerate(out):
            x = row[1] + dist[k] * math.cos(self.start_angle[k])
            y = row[2] + dist[k] * math.sin(self.start_angle[k])
            if dist[k] > 0 and mazes[int(row[0])].clearance(x, y) >= robot_radius:
                row[1], row[2] = x, y
            row[3] += turn[k]
        return out


def perturbation_dir() -> Path:
    """Folder of the shipped perturbation sets."""
    return config_dir() / "perturbations"


def is_set_file(name_or_path: str) -> bool:
    """True if ``name_or_path`` names a perturbation set file (a path), not a set's name."""
    return name_or_path.endswith((".yaml", ".yml")) or os.sep in name_or_path


def load_perturbations(name_or_path: str | os.PathLike) -> PerturbationSet:
    """``none``, a shipped set by name (``realistic``) or a set file by path.

    Raises:
        ConfigError: unknown name (listing the shipped ones) or a bad file.
    """
    text = str(name_or_path)
    if text == "none":
        return NONE
    if not is_set_file(text):
        path = perturbation_dir() / f"{text}.yaml"
        if not path.is_file():
            known = sorted(p.stem for p in perturbation_dir().glob("*.yaml"))
            raise ConfigError(
                f"unknown perturbation set {text!r}; known: none, {', '.join(known)}, or a file"
            )
        text = str(path)
    return PerturbationSet.from_dict(load_yaml_mapping(text), text)
