"""A legged robot's periodic gait: the paper's eq. 10-11 for any number of legs and joints.

This module says what a legged primitive *is* (its parameters and the joint targets it
gives at every instant) for any robot described by a settings file
(``config/robots/*.yaml``, docs/legged.md). The onboard primitive executor and the
PyBullet simulation both use it, so it depends on numpy and pyyaml only.

A gait has *oscillators*, the evolved quantities, and *joints*, the actuated joints in
command order. Oscillator ``i`` follows eq. 10 and maps onto its range ``[low_i, high_i]``
(rad)::

    p_i(t) = eps_i + alpha_i * tanh(rho * sin(2 pi (t omega + phi_i)))      (eq. 10)
    e_i(t) = centre_i + clip(p_i(t), -1, 1) * half_i                       (rad)

with ``centre_i, half_i`` the middle and half-width of the range, and each joint's target
is a linear *coupling* of the oscillators::

    q_k(t) = constant_k + sum_i c_ki e_i(t)                                (rad)

An oscillator usually drives one joint (``q_k = e_i``); the hexapod's shin keeps its tibia
vertical with ``C = 90 deg - B`` (paper Appendix D), and the A1's thigh follows the swing
and the knee so that the foot stays under the hip (docs/a1.md). A primitive is
``[rho, eps_1, alpha_1, phi_1, ..., eps_n, alpha_n, phi_n]`` over the ``n`` oscillators
(eq. 11), ``1 + 3 n`` genes in [-1, 1]; ``t`` counts whole servo steps since the gait began
(:func:`gait_step_times`), so the simulation and the executor sample eq. 10 at the same
times and consecutive primitives continue one clock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from evorbc_ros.config import ConfigError
from evorbc_ros.robots.primitive import ParameterSpec

#: Smoothness rho of eq. 10: pi/8 (close to a sine) to pi/8 + 2 pi (close to a square).
RHO_LOW, RHO_HIGH = math.pi / 8.0, math.pi / 8.0 + 2.0 * math.pi


@dataclass(frozen=True)
class Oscillator:
    """One evolved quantity of eq. 10, mapped onto ``[low, high]`` rad.

    ``mirror`` names the oscillator that plays this one's part in the robot's left/right
    mirror image (itself for one on the robot's mid-plane); ``mirror_sign`` is -1 when the
    mirror image's angle is the negative of this one's (a hip abduction), +1 otherwise.
    """

    name: str
    low: float  # rad, e at p = -1
    high: float  # rad, e at p = +1
    mirror: str | None = None
    mirror_sign: float = 1.0

    @property
    def centre(self) -> float:
        """rad, e at p = 0 (the standing pose)."""
        return 0.5 * (self.low + self.high)

    @property
    def half(self) -> float:
        """rad, half the range."""
        return 0.5 * (self.high - self.low)


@dataclass(frozen=True)
class JointDrive:
    """An actuated joint's target: ``constant + sum(coefficient x oscillator)`` (rad)."""

    name: str
    constant: float  # rad
    terms: tuple[tuple[int, float], ...]  # (oscillator index, coefficient)


@dataclass(frozen=True)
class Gait:
    """A robot's periodic gait: oscillators, joint couplings and the frequency omega."""

    oscillators: tuple[Oscillator, ...]
    joints: tuple[JointDrive, ...]
    frequency: float = 1.0  # Hz, omega of eq. 10

    def __post_init__(self) -> None:
        # Coupling terms grouped by their position in each joint's list, so that
        # :meth:`drive` adds them in the order written, whatever the number of rows.
        layers = []
        depth = max((len(j.terms) for j in self.joints), default=0)
        for r in range(depth):
            cols = [k for k, j in enumerate(self.joints) if len(j.terms) > r]
            srcs = [self.joints[k].terms[r][0] for k in cols]
            coeffs = [self.joints[k].terms[r][1] for k in cols]
            layers.append((np.array(cols), np.array(srcs), np.array(coeffs, dtype=np.float64)))
        object.__setattr__(self, "_layers", tuple(layers))

    @property
    def n_parameters(self) -> int:
        """Genes of a primitive: rho plus (offset, amplitude, phase) per oscillator."""
        return 1 + 3 * len(self.oscillators)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Actuated joints in command order."""
        return tuple(j.name for j in self.joints)

    def centres(self) -> np.ndarray:
        """``(n,)`` rad, each oscillator's centre."""
        return np.array([o.centre for o in self.oscillators])

    def halves(self) -> np.ndarray:
        """``(n,)`` rad, each oscillator's half range."""
        return np.array([o.half for o in self.oscillators])

    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """Names, units and ranges of the ``1 + 3 n`` parameters (eq. 11), genes in [-1, 1]."""
        specs = [ParameterSpec("rho", "1", RHO_LOW, RHO_HIGH)]
        for o in self.oscillators:
            specs += [
                ParameterSpec(f"{o.name}.offset", "joint range", -1.0, 1.0),
                ParameterSpec(f"{o.name}.amplitude", "joint range", 0.0, 1.0),
                ParameterSpec(f"{o.name}.phase", "cycle", 0.0, 1.0),
            ]
        return tuple(specs)

    def drive(self, evolved: np.ndarray) -> np.ndarray:
        """``(m, joints)`` joint targets (rad) from ``(m, n)`` oscillator values (rad)."""
        evolved = np.atleast_2d(evolved)
        q = np.empty((evolved.shape[0], len(self.joints)))
        q[:] = [j.constant for j in self.joints]
        for cols, srcs, coeffs in self._layers:
            q[:, cols] += coeffs * evolved[:, srcs]
        return q

    def standing_pose(self) -> np.ndarray:
        """``(joints,)`` rad: every oscillator at its centre."""
        return self.drive(self.centres())[0]

    def mirror_genes(self, genes: np.ndarray) -> np.ndarray:
        """Primitives of the left/right mirror image: each oscillator takes its mirror's genes.

        With ``mirror_sign`` -1 the mirror oscillator runs ``-p``: its offset changes sign
        and its phase moves half a cycle (tanh and sine are odd), so ``e`` becomes the
        mirror angle. The mirrored robot's displacement ``(x, y)`` becomes ``(x, -y)`` and
        its heading ``-heading``.
        """
        g = np.array(genes, dtype=np.float64, copy=True)
        src = np.asarray(genes, dtype=np.float64)
        index = {o.name: i for i, o in enumerate(self.oscillators)}
        for i, o in enumerate(self.oscillators):
            j = index[o.mirror or o.name]
            g[..., 1 + 3 * j : 4 + 3 * j] = src[..., 1 + 3 * i : 4 + 3 * i]
            if o.mirror_sign < 0:
                g[..., 1 + 3 * j] = -src[..., 1 + 3 * i]
                phase = src[..., 3 + 3 * i]  # gene -1..1 is phase 0..1 cycle
                g[..., 3 + 3 * j] = np.where(phase < 0.0, phase + 1.0, phase - 1.0)
        return g


class LeggedGaitTable:
    """Primitives in physical units, ready to give joint targets at any time.

    Args:
        genes: ``(n, 1 + 3 k)`` or ``(1 + 3 k,)`` genes in [-1, 1] (clipped).
        gait: the robot's gait (``k`` oscillators).
        robot: the robot's name, for the error message.

    """

    def __init__(self, genes: np.ndarray, gait: Gait, robot: str = "legged"):
        g = np.clip(np.atleast_2d(np.asarray(genes, dtype=np.float64)), -1.0, 1.0)
        if g.shape[1] != gait.n_parameters:
            raise ValueError(f"{robot} primitives have {gait.n_parameters} genes, got {g.shape[1]}")
        self.gait = gait
        unit = 0.5 * (g + 1.0)  # [-1, 1] -> [0, 1]
        self.rho = RHO_LOW + unit[:, 0] * (RHO_HIGH - RHO_LOW)  # (n,)
        self.offset = g[:, 1::3]  # (n, k) oscillator-range units
        self.amplitude = unit[:, 2::3]  # (n, k)
        self.phase = unit[:, 3::3]  # (n, k) cycles
        self.centres = gait.centres()
        self.limits = gait.halves()

    def __len__(self) -> int:
        return len(self.rho)

    def evolved_targets(self, t: float | np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """Eq. 10 values (rad) of the oscillators at time ``t`` (s).

        Args:
            t: scalar, or ``(m,)`` times (one per selected row).
            rows: which primitives (default: all).

        Returns:
            ``(m, k)`` rad.

        """
        sel = slice(None) if rows is None else rows
        t = np.asarray(t, dtype=np.float64)
        t_col = t[:, None] if t.ndim else t
        wave = np.sin(2.0 * math.pi * (t_col * self.gait.frequency + self.phase[sel]))
        p = self.offset[sel] + self.amplitude[sel] * np.tanh(self.rho[sel][:, None] * wave)
        return np.clip(p, -1.0, 1.0) * self.limits + self.centres

    def joint_targets(self, t: float | np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """All joint targets (rad) at time ``t`` (s), couplings applied; ``(m, joints)``."""
        return self.gait.drive(self.evolved_targets(t, rows))


def gait_step_times(first_step: int, steps: int, dt: float) -> np.ndarray:
    """Gait times (s) of servo steps ``first_step, first_step + 1, ...``: ``n * dt``.

    The simulation and the onboard executor both count whole steps since the gait began
    and multiply once, so they sample eq. 10 at bit-identical times.
    """
    return (first_step + np.arange(steps)) * dt


# -- settings files ---------------------------------------------------------------------


def _number(value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(f"{where}: expected a finite number, got {value!r}")
    return float(value)


def _angle_pair(entry: dict, where: str) -> tuple[float, float]:
    """``range_deg: [low, high]`` (deg) or ``range: [low, high]`` (rad) -> rad."""
    if ("range_deg" in entry) == ("range" in entry):
        raise ConfigError(f"{where}: give exactly one of range_deg (deg) and range (rad)")
    key = "range_deg" if "range_deg" in entry else "range"
    pair = entry[key]
    if not isinstance(pair, list) or len(pair) != 2:
        raise ConfigError(f"{where}.{key}: expected [low, high]")
    low, high = (_number(v, f"{where}.{key}") for v in pair)
    if not low < high:
        raise ConfigError(f"{where}.{key}: expected low < high, got [{low:g}, {high:g}]")
    if key == "range_deg":
        low, high = math.radians(low), math.radians(high)
    return low, high


def _oscillators(data, where: str) -> tuple[Oscillator, ...]:
    if not isinstance(data, dict) or not data:
        raise ConfigError(f"{where}: expected a mapping of oscillator names to settings")
    out = []
    for name, entry in data.items():
        here = f"{where}.{name}"
        if not isinstance(entry, dict):
            raise ConfigError(f"{here}: expected a mapping (range_deg, mirror, mirror_sign)")
        unknown = set(entry) - {"range_deg", "range", "mirror", "mirror_sign"}
        if unknown:
            raise ConfigError(f"{here}: unknown key {sorted(unknown)[0]!r}")
        low, high = _angle_pair(entry, here)
        sign = entry.get("mirror_sign", 1)
        if sign not in (1, -1):
            raise ConfigError(f"{here}.mirror_sign: expected 1 or -1, got {sign!r}")
        mirror = entry.get("mirror", str(name))
        out.append(Oscillator(str(name), low, high, str(mirror), float(sign)))
    names = {o.name: o for o in out}
    for o in out:
        partner = names.get(o.mirror)
        here = f"{where}.{o.name}.mirror"
        if partner is None:
            raise ConfigError(f"{here}: no oscillator {o.mirror!r}; known: {', '.join(names)}")
        if partner.mirror != o.name or partner.mirror_sign != o.mirror_sign:
            raise ConfigError(f"{here}: {o.mirror} must name {o.name} back, with the same sign")
        want = (o.low, o.high) if o.mirror_sign > 0 else (-o.high, -o.low)
        if not np.allclose((partner.low, partner.high), want, rtol=0.0, atol=1e-12):
            raise ConfigError(f"{here}: {o.mirror}'s range must mirror {o.name}'s")
    return tuple(out)


def _joints(data, oscillators: tuple[Oscillator, ...], where: str) -> tuple[JointDrive, ...]:
    if not isinstance(data, dict) or not data:
        raise ConfigError(f"{where}: expected a mapping of joint names to couplings")
    index = {o.name: i for i, o in enumerate(oscillators)}
    out, used = [], set()
    for name, entry in data.items():
        here = f"{where}.{name}"
        if not isinstance(entry, dict) or not entry:
            raise ConfigError(
                f"{here}: expected a mapping of oscillator names to coefficients, "
                "and optionally constant_deg or constant (rad)"
            )
        constant, terms = 0.0, []
        for key, value in entry.items():
            if key == "constant_deg":
                constant = math.radians(_number(value, f"{here}.{key}"))
            elif key == "constant":
                constant = _number(value, f"{here}.{key}")
            elif key in index:
                terms.append((index[key], _number(value, f"{here}.{key}")))
                used.add(key)
            else:
                raise ConfigError(f"{here}: {key!r} is no oscillator; known: {', '.join(index)}")
        out.append(JointDrive(str(name), constant, tuple(terms)))
    unused = [o.name for o in oscillators if o.name not in used]
    if unused:
        raise ConfigError(f"{where}: oscillator {unused[0]!r} drives no joint")
    return tuple(out)


def gait_from_settings(data: dict, source: str) -> Gait:
    """The gait of a legged robot's settings (``oscillators``, ``joints``, ``gait``).

    Raises:
        ConfigError: one line naming ``source`` and the key.

    """
    oscillators = _oscillators(data.get("oscillators"), f"{source}: oscillators")
    joints = _joints(data.get("joints"), oscillators, f"{source}: joints")
    gait = data.get("gait", {})
    if not isinstance(gait, dict) or set(gait) - {"frequency_hz"}:
        raise ConfigError(f"{source}: gait: expected a mapping with frequency_hz")
    frequency = _number(gait.get("frequency_hz", 1.0), f"{source}: gait.frequency_hz")
    if frequency <= 0.0:
        raise ConfigError(f"{source}: gait.frequency_hz: expected > 0, got {frequency:g}")
    return Gait(oscillators, joints, frequency)
