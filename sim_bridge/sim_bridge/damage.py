"""Damage in a perturbation set: one broken wheel, leg or side per episode (docs/perturbations.md).

A set's optional ``damage`` mapping names one *kind* of damage, the *part* it hits and the
range of its *level*; every episode draws the part (when the set says ``any``) and the
level from its own row key (``default_rng([key, 2])``), so drawing damage takes nothing
from the generator the rest of the set is drawn from: a set without damage draws exactly
what it drew before, and an episode's damage does not depend on other episodes.

Kinds, the family that applies them, the parts and what the level means:

========================  ========  =================  =========================================
kind                      family    part               level
========================  ========  =================  =========================================
``stuck_steering``        4WS       wheel (fl ... rr)  deg, the stuck angle's size (sign drawn)
``slow_wheel``            4WS       wheel              share of its commanded speed it turns at
``slipping_wheel``        4WS       wheel              largest share of traction lost per cycle
``leg_lost``              legged    leg (index)        none: the leg's links are gone
``leg_limp``              legged    leg                none: the leg's servos go limp
``knee_locked``           legged    leg                none: the knee held at its start angle
``weak_leg``              legged    leg                share of the leg's servo torque left
``weak_side``             legged    left / right       share of the side's servo torque left
========================  ========  =================  =========================================

A part drawn as ``any`` is kept as a uniform number ``u`` in [0, 1) and becomes part
``floor(u x n)`` of a robot with ``n`` parts, so one draw serves every robot of the family.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from evorbc_ros.config import ConfigError

#: The 4WS wheels in state order (sim_bridge/four_ws/motion.py).
WHEELS = ("fl", "fr", "rl", "rr")
SIDES = ("left", "right")
#: kind -> (family, part kind, level key or None, level bounds).
KINDS = {
    "stuck_steering": ("four_ws", "wheel", "angle_deg", (0.0, 90.0)),
    "slow_wheel": ("four_ws", "wheel", "speed_factor", (0.0, 1.0)),
    "slipping_wheel": ("four_ws", "wheel", "slip", (0.0, 1.0)),
    "leg_lost": ("legged", "leg", None, (0.0, 0.0)),
    "leg_limp": ("legged", "leg", None, (0.0, 0.0)),
    "knee_locked": ("legged", "leg", None, (0.0, 0.0)),
    "weak_leg": ("legged", "leg", "strength", (0.0, 1.0)),
    "weak_side": ("legged", "side", "strength", (0.0, 1.0)),
}
#: Codes of the 4WS kinds in the compiled kernel (0: intact).
FOUR_WS_CODES = {"stuck_steering": 1, "slow_wheel": 2, "slipping_wheel": 3}
#: The kinds each family's simulation applies (a task's ``damage_applied``).
FOUR_WS_DAMAGE = tuple(k for k, v in KINDS.items() if v[0] == "four_ws")
LEGGED_DAMAGE = tuple(k for k, v in KINDS.items() if v[0] == "legged")


def number_pair(v) -> bool:
    """Whether ``v`` is a ``[low, high]`` of two finite numbers (a YAML list; not bools)."""
    return (
        isinstance(v, (list, tuple))
        and len(v) == 2
        and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)
        and all(math.isfinite(x) for x in v)
    )


@dataclass(frozen=True)
class DamageSpec:
    """One kind of damage: the part it hits (``any`` or a name/index) and its level range."""

    kind: str
    part: str = "any"
    level: tuple[float, float] = (0.0, 0.0)

    @classmethod
    def from_dict(cls, data, source: str) -> DamageSpec:
        """The ``damage`` mapping of a set file.

        Raises:
            ConfigError: one line naming ``source`` and the key: unknown kind or key, a
                part this kind has not, a level range outside its bounds.
        """
        if not isinstance(data, dict):
            raise ConfigError(f"{source}: damage must be a mapping with kind, part and a level")
        kind = data.get("kind")
        if kind not in KINDS:
            raise ConfigError(
                f"{source}: damage.kind must be one of {', '.join(KINDS)}; got {kind!r}"
            )
        _, part_kind, level_key, (low, high) = KINDS[kind]
        known = {"kind", "part"} | ({level_key} if level_key else set())
        for key in data:
            if key not in known:
                raise ConfigError(
                    f"{source}: damage: unknown key {key!r} for {kind}; known: "
                    f"{', '.join(sorted(known))}"
                )
        part = data.get("part", "any")
        parts = {"wheel": WHEELS, "side": SIDES}.get(part_kind)
        if isinstance(part, bool) or not (
            part == "any"
            or (parts is not None and part in parts)
            or (part_kind == "leg" and isinstance(part, int) and 0 <= part < 32)
        ):
            wanted = f"any or one of {', '.join(parts)}" if parts else "any or a leg index 0-31"
            raise ConfigError(f"{source}: damage.part must be {wanted}; got {part!r}")
        level = (0.0, 0.0)
        if level_key:
            if level_key not in data:
                raise ConfigError(f"{source}: damage.{level_key} is missing ([low, high])")
            v = data[level_key]
            if not number_pair(v) or not (low <= v[0] <= v[1] <= high):
                raise ConfigError(
                    f"{source}: damage.{level_key} must be [low, high] with {low:g} <= low <= "
                    f"high <= {high:g}; got {v!r}"
                )
            level = (float(v[0]), float(v[1]))
        return cls(kind=kind, part=str(part), level=level)

    @property
    def family(self) -> str:
        """``four_ws`` or ``legged``."""
        return KINDS[self.kind][0]

    def as_dict(self) -> dict:
        """Plain-data form (reports), the level under its own key."""
        out = {"kind": self.kind, "part": self.part}
        if KINDS[self.kind][2]:
            out[KINDS[self.kind][2]] = list(self.level)
        return out

    def draw(self, keys: np.ndarray) -> DamageDraw:
        """One damage per row key ``keys (S,)``: from ``default_rng([key, 2])`` each."""
        part_u, level, sign = np.empty(len(keys)), np.empty(len(keys)), np.empty(len(keys))
        lo, hi = self.level
        for k, key in enumerate(keys):
            rng = np.random.default_rng([int(key), 2])
            u = rng.random(3)
            part_u[k] = u[0]
            level[k] = lo + u[1] * (hi - lo)
            sign[k] = 1.0 if u[2] < 0.5 else -1.0
        return DamageDraw(self, part_u, level, sign)


@dataclass(frozen=True)
class DamageDraw:
    """Per start row: the drawn part (``part_u`` in [0, 1)), level and sign."""

    spec: DamageSpec
    part_u: np.ndarray  # (S,)
    level: np.ndarray  # (S,) in the kind's unit (deg, share)
    sign: np.ndarray  # (S,) +1 or -1 (the stuck angle's side)

    def part(self, k: int, names: tuple[str, ...]) -> int:
        """Row ``k``'s part, an index into ``names`` (the robot's wheels, legs or sides).

        Raises:
            ConfigError: the set fixes a part this robot has not.
        """
        part = self.spec.part
        if part == "any":
            return min(int(self.part_u[k] * len(names)), len(names) - 1)
        if part in names:
            return names.index(part)
        if part.isdigit() and int(part) < len(names):
            return int(part)
        raise ConfigError(
            f"damage.part {part!r}: this robot's parts are {', '.join(names)} "
            f"(legs by index 0-{len(names) - 1})"
        )

    def row(self, k: int) -> dict:
        """Row ``k`` as plain data (sent to PyBullet workers)."""
        return {
            "kind": self.spec.kind,
            "part": self.spec.part,
            "part_u": float(self.part_u[k]),
            "level": float(self.level[k]),
            "sign": float(self.sign[k]),
        }

    def wheel_arrays(self) -> np.ndarray:
        """``(S, 3)`` for the 4WS kernel: kind code, wheel index, level.

        The level is the stuck angle in rad (signed), the speed factor or the slip share.
        """
        code = FOUR_WS_CODES[self.spec.kind]
        rows = []
        for k in range(len(self.level)):
            level = self.level[k]
            if self.spec.kind == "stuck_steering":
                level = math.radians(level) * self.sign[k]
            rows.append((float(code), float(self.part(k, WHEELS)), level))
        return np.asarray(rows, dtype=np.float64).reshape(-1, 3)


def part_names(kind: str, legs: tuple[str, ...] = ()) -> tuple[str, ...]:
    """The parts ``kind`` can hit: the 4WS wheels, the sides, or ``legs`` (foot links)."""
    return {"wheel": WHEELS, "side": SIDES, "leg": legs}[KINDS[kind][1]]


def describe(row: dict, names: tuple[str, ...]) -> tuple[str, str]:
    """``(part name, one line for a report)`` of a :meth:`DamageDraw.row` dict ``row``.

    ``names``: the robot's parts of the kind (:func:`part_names`).
    """
    spec = DamageSpec(row["kind"], row["part"])
    draw = DamageDraw(spec, np.array([row["part_u"]]), np.array([row["level"]]), np.array([1]))
    part = names[draw.part(0, names)]
    level = row["level"]
    text = {
        "stuck_steering": f"steering stuck at {level * row['sign']:+.1f} deg",
        "slow_wheel": f"turning at {level:.2f} of its speed",
        "slipping_wheel": f"losing up to {level:.2f} of its traction",
        "leg_lost": "lost",
        "leg_limp": "limp",
        "knee_locked": "knee locked",
        "weak_leg": f"servos at {level:.2f} torque",
        "weak_side": f"servos at {level:.2f} torque",
    }[row["kind"]]
    return part, f"{row['kind']}: {part} {text}"
