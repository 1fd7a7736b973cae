"""What the gait design search may change, and within which bounds (docs/legged.md).

A design is the servo gain (1/s), the gait frequency (Hz), the physics rate (Hz) and, per
group of oscillators (``FL_swing``, ``FR_swing``, ... form the group ``swing``), a scale of
their half ranges about their centres (the standing pose stays the settings file's). The
bounds come from the robot:

* gain 2 to 45 /s, log-uniform: at 50 Hz, the slowest rate, gain x step stays below 1,
  where the implicit servo is stable (sim_bridge/legged/physics.py);
* frequency 0.4 to 2 times the file's (for a robot from a URDF, the A1's 2.5 Hz scaled to
  equal Froude number), log-uniform;
* physics rates of :data:`RATES` making the control period and settle time whole steps;
* scales 0.2 to 2 times the file's half ranges, cut so that every joint a group drives
  stays inside its URDF ``<limit>`` while the other oscillators stand.

Values are rounded (gain 0.1 /s, frequency 0.05 Hz, scale 0.01, range ends 0.1 deg) so
that the design scored is the design written, bit for bit.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sim_bridge.legged.gait_measures import joint_limits
from sim_bridge.legged.settings import LeggedRobotSettings, robot_settings_from_mapping

#: Hz, the physics rates tried (docs/a1.md and docs/hexapod.md measured these).
RATES = (50.0, 100.0, 150.0, 200.0, 250.0, 500.0)
GAIN = (2.0, 45.0)  # 1/s
FREQUENCY = (0.4, 2.0)  # times the file's
SCALE = (0.2, 2.0)  # times the file's half ranges


def group_of(oscillator: str) -> str:
    """The group an oscillator belongs to: its name after the leg's (``FL_swing``: swing)."""
    return oscillator.split("_", 1)[1] if "_" in oscillator else oscillator


def _whole_steps(rate: float, durations: tuple[float, ...]) -> bool:
    return all(abs(round(d * rate) - d * rate) < 1e-9 for d in durations)


@dataclass(frozen=True)
class DesignSpace:
    """The bounded design space of one settings file.

    ``data`` is the file's mapping, ``path`` the file (it anchors a relative URDF).
    """

    data: dict
    path: Path
    settings: LeggedRobotSettings
    groups: tuple[str, ...]
    scale_max: tuple[float, ...]  # per group
    rates: tuple[float, ...]

    @classmethod
    def of(cls, data: dict, path: Path) -> DesignSpace:
        """The space of the settings mapping ``data`` read from ``path``."""
        settings = robot_settings_from_mapping(data, path)
        gait = settings.gait
        groups = tuple(dict.fromkeys(group_of(o.name) for o in gait.oscillators))
        low, high = joint_limits(settings)
        standing = gait.standing_pose()
        scale_max = []
        for g in groups:
            bound = SCALE[1]
            for j, drive in enumerate(gait.joints):
                sweep = sum(
                    abs(c) * gait.oscillators[i].half
                    for i, c in drive.terms
                    if group_of(gait.oscillators[i].name) == g
                )
                if sweep > 0:
                    room = min(high[j] - standing[j], standing[j] - low[j])
                    bound = min(bound, room / sweep)
            # A range already at its limit (the hexapod's) stays reachable: 1e-6 slack.
            scale_max.append(max(SCALE[0], math.floor((bound + 1e-6) * 100.0) / 100.0))
        durations = (settings.control_period, settings.physics.settle_time)
        rates = tuple(r for r in RATES if _whole_steps(r, durations))
        return cls(copy.deepcopy(data), Path(path), settings, groups, tuple(scale_max), rates)

    @property
    def dimensions(self) -> int:
        """Unit-cube dimensions: gain, frequency, rate, one scale per group."""
        return 3 + len(self.groups)

    def current(self) -> dict:
        """The file's own design, as values."""
        s = self.settings
        return {
            "gain": s.servo.gain,
            "frequency_hz": s.gait.frequency,
            "rate_hz": s.physics.rate,
            "scale": {g: 1.0 for g in self.groups},
        }

    def from_unit(self, u: np.ndarray) -> dict:
        """The (rounded) design at point ``u`` of the unit cube ``(dimensions,)``."""
        u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
        f0 = self.settings.gait.frequency
        gain = math.exp(math.log(GAIN[0]) + u[0] * math.log(GAIN[1] / GAIN[0]))
        freq = f0 * math.exp(math.log(FREQUENCY[0]) + u[1] * math.log(FREQUENCY[1] / FREQUENCY[0]))
        rate = self.rates[min(int(u[2] * len(self.rates)), len(self.rates) - 1)]
        scale = {
            g: round(SCALE[0] + u[3 + k] * (self.scale_max[k] - SCALE[0]), 2)
            for k, g in enumerate(self.groups)
        }
        return {
            "gain": round(gain, 1),
            "frequency_hz": max(0.05, round(freq * 20.0) / 20.0),
            "rate_hz": rate,
            "scale": scale,
        }

    def to_unit(self, values: dict) -> np.ndarray:
        """The unit-cube point of ``values`` (the inverse of :meth:`from_unit`, unrounded)."""
        f0 = self.settings.gait.frequency
        u = [
            math.log(values["gain"] / GAIN[0]) / math.log(GAIN[1] / GAIN[0]),
            math.log(values["frequency_hz"] / f0 / FREQUENCY[0])
            / math.log(FREQUENCY[1] / FREQUENCY[0]),
            (self.rates.index(values["rate_hz"]) + 0.5) / len(self.rates)
            if values["rate_hz"] in self.rates
            else 0.5,
        ]
        for k, g in enumerate(self.groups):
            span = self.scale_max[k] - SCALE[0]
            u.append((values["scale"][g] - SCALE[0]) / span if span > 0 else 0.0)
        return np.clip(np.array(u), 0.0, 1.0)

    def ranges_deg(self, values: dict) -> dict[str, list[float]]:
        """Each oscillator's ``[low, high]`` deg under ``values`` (centres kept)."""
        out = {}
        for o in self.settings.gait.oscillators:
            s = values["scale"][group_of(o.name)]
            if s == 1.0:
                out[o.name] = _file_range_deg(self.data["oscillators"][o.name])
                continue
            c, h = math.degrees(o.centre), math.degrees(o.half) * s
            out[o.name] = [round(c - h, 1) + 0.0, round(c + h, 1) + 0.0]
        return out

    def mapping(self, values: dict) -> dict:
        """The settings file's mapping with ``values`` in place."""
        data = copy.deepcopy(self.data)
        data["servo"]["gain"] = values["gain"]
        data["gait"]["frequency_hz"] = values["frequency_hz"]
        data["physics"]["rate_hz"] = values["rate_hz"]
        for name, pair in self.ranges_deg(values).items():
            entry = data["oscillators"][name]
            entry.pop("range", None)
            entry["range_deg"] = pair
        return data

    def design(self, values: dict) -> LeggedRobotSettings:
        """The robot with ``values`` in place."""
        return robot_settings_from_mapping(self.mapping(values), self.path)


def _file_range_deg(entry: dict) -> list[float]:
    """An oscillator's range as the file gives it, in deg."""
    if "range_deg" in entry:
        return [float(v) for v in entry["range_deg"]]
    return [math.degrees(v) for v in entry["range"]]


def key(values: dict) -> str:
    """A design's identity (equal designs, equal keys)."""
    scale = ",".join(f"{g}={s!r}" for g, s in sorted(values["scale"].items()))
    return f"{values['gain']!r}/{values['frequency_hz']!r}/{values['rate_hz']!r}/{scale}"
