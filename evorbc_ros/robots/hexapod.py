"""The hexapod: 6 legs of 3 joints, and its 37-parameter periodic gait (paper eq. 10-11).

This module says what a hexapod primitive *is*: its parameters and the joint targets it
gives at every instant. The onboard primitive executor and the PyBullet simulation both
use it, so it depends on numpy only.

Frames follow REP 103: body x forward, y left, z up. Legs are numbered 1..6 in the order
``lf, lm, lr, rf, rm, rr`` (left front, left middle, left rear, right front, ...). Each leg
has three revolute joints (paper Fig. 15 and Appendix D):

- ``A`` (``<leg>_coxa``): yaw of the whole leg, in [-70, 70] deg. Positive swings the foot
  towards the front (+x) on *both* sides, so mirroring the robot left to right maps a
  primitive onto itself with left and right legs swapped and no sign change.
- ``B`` (``<leg>_femur``): pitch of the thigh, in [-90, 90] deg. Positive lowers the knee
  (pushes the body up); 0 holds the thigh level.
- ``C`` (``<leg>_tibia``): pitch of the shin, never evolved: ``C = -B + 90 deg`` keeps the
  shin vertical, perpendicular to the body (paper Appendix D).

A primitive is ``[rho, eps_1, alpha_1, phi_1, ..., eps_12, alpha_12, phi_12]`` over the 12
evolved joints in the order ``A1, B1, A2, B2, ..., A6, B6``. Joint ``j`` tracks::

    p_j(t) = eps_j + alpha_j * tanh(rho * sin(2 pi (t omega + phi_j)))    (eq. 10)
    target_j(t) = clip(p_j(t), -1, 1) * limit_j                          (rad)

with omega = 1 Hz and ``t`` the time since the primitive's evaluation (or the episode)
began, so consecutive primitives continue one clock and the gait stays smooth when the
arbitrator switches.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from evorbc_ros.robots.primitive import ParameterSpec

#: Robot name used in files, settings and on the command line.
HEXAPOD = "hexapod"
#: Legs in the order of the paper's indices 1..6.
LEG_NAMES = ("lf", "lm", "lr", "rf", "rm", "rr")
#: Joint names of one leg, from the body outwards (paper A, B, C).
LEG_JOINTS = ("coxa", "femur", "tibia")
#: All 18 joint names in the order of joint-state and command vectors: leg by leg,
#: A, B, C within a leg.
JOINT_NAMES = tuple(f"{leg}_{joint}" for leg in LEG_NAMES for joint in LEG_JOINTS)
#: Evolved joints (A1, B1, ..., A6, B6): indices into :data:`JOINT_NAMES`.
EVOLVED_JOINTS = tuple(3 * leg + k for leg in range(6) for k in (0, 1))
#: Smoothness rho of eq. 10: pi/8 (close to a sine) to pi/8 + 2 pi (close to a square).
RHO_LOW, RHO_HIGH = math.pi / 8.0, math.pi / 8.0 + 2.0 * math.pi
#: Number of primitive parameters: rho plus (offset, amplitude, phase) for 12 joints.
N_PARAMETERS = 1 + 3 * len(EVOLVED_JOINTS)

#: Displacement speed (m/s) no hexapod gait reaches: the archive spans this speed times T
#: in every direction. The fastest primitives of a 200k-evaluation repertoire reach
#: 0.51 m/s (1.01 m in 2 s, docs/hexapod.md); anything beyond the bound would be a
#: simulation blow-up.
SPEED_BOUND = 0.6

#: Hz, the servo loop: one joint target per physics step of the simulation
#: (docs/hexapod.md says why 50), so a 0.1 s control period is 5 targets.
SERVO_RATE = 50.0


@dataclass(frozen=True)
class HexapodGeometry:
    """Dimensions, masses and actuators of the simulated hexapod (docs/hexapod.md).

    The V-REP model the paper used is not published; these are a realistic small hexapod
    of about 2.5 kg whose servos resemble standard hobby servos under load (2.5 N m,
    0.21 s per 60 deg). The short shin and slow servos keep it upright when the arbitrator
    switches gaits every cycle (bench/bench_hexapod_stability.py).
    Lengths in m, masses in kg, angles in rad.
    """

    body_length: float = 0.24  # m, along x
    body_width: float = 0.20  # m, along y
    body_height: float = 0.04  # m, along z
    body_mass: float = 1.0  # kg
    coxa_length: float = 0.06  # m, hip (A) axis to femur (B) axis
    femur_length: float = 0.085  # m, B axis to C axis
    tibia_length: float = 0.10  # m, C axis to the centre of the foot sphere
    coxa_mass: float = 0.05  # kg
    femur_mass: float = 0.08  # kg
    tibia_mass: float = 0.12  # kg
    segment_radius: float = 0.01  # m, leg segments are rods of this radius (inertia only)
    foot_radius: float = 0.012  # m, the only leg part that touches anything
    #: Neutral (A = 0) direction of each leg in the body frame, deg from +x, legs in
    #: :data:`LEG_NAMES` order: front legs splay forward, rear legs backward.
    leg_yaw_deg: tuple[float, ...] = (45.0, 90.0, 135.0, -45.0, -90.0, -135.0)
    coxa_limit: float = math.radians(70.0)  # |A| (paper Appendix D)
    femur_limit: float = math.radians(90.0)  # |B| (paper Appendix D)
    coxa_torque: float = 2.5  # N m, largest torque the A servo applies
    femur_torque: float = 2.5  # N m, B servo
    tibia_torque: float = 2.5  # N m, C servo
    max_joint_velocity: float = 5.0  # rad/s (0.21 s per 60 deg)
    position_gain: float = 20.0  # 1/s, commanded joint velocity per rad of error
    frequency: float = 1.0  # Hz, omega of eq. 10 (paper Appendix D)
    control_period: float = 0.1  # s, the arbitrator's cycle

    def hip_positions(self) -> np.ndarray:
        """``(6, 2)`` hip (A axis) positions in the body frame, m, legs in order.

        Front and rear legs sit at the body's corners, middle legs at the middle of its
        sides.
        """
        x, y = 0.5 * self.body_length, 0.5 * self.body_width
        return np.array([[x, y], [0.0, y], [-x, y], [x, -y], [0.0, -y], [-x, -y]])

    @property
    def footprint_radius(self) -> float:
        """Radius (m) of the circle about the body centre that holds every foot.

        Feet in the neutral pose (A = B = 0: femur level, shin vertical), foot sphere
        included; start poses keep this circle clear of walls.
        """
        yaw = np.radians(self.leg_yaw_deg)
        reach = self.coxa_length + self.femur_length  # m, hip to foot in the ground plane
        feet = self.hip_positions() + reach * np.column_stack([np.cos(yaw), np.sin(yaw)])
        return float(np.hypot(feet[:, 0], feet[:, 1]).max()) + self.foot_radius

    @property
    def total_mass(self) -> float:
        """kg, body and six legs."""
        return self.body_mass + 6.0 * (self.coxa_mass + self.femur_mass + self.tibia_mass)

    @property
    def standing_height(self) -> float:
        """m, height of the body centre above the ground in the neutral pose (B = 0)."""
        return self.tibia_length + self.foot_radius

    def joint_limits(self) -> np.ndarray:
        """``(18,)`` rad, the largest |target| of each joint (C: its upper bound, pi)."""
        per_leg = [self.coxa_limit, self.femur_limit, math.pi]
        return np.array(per_leg * 6)

    def joint_torques(self) -> np.ndarray:
        """``(18,)`` N m, the torque limit of each joint."""
        return np.array([self.coxa_torque, self.femur_torque, self.tibia_torque] * 6)

    def evolved_limits(self) -> np.ndarray:
        """``(12,)`` rad, the scale of eq. 10's output for A1, B1, ..., A6, B6."""
        return np.array([self.coxa_limit, self.femur_limit] * 6)

    def neutral_pose(self) -> np.ndarray:
        """``(18,)`` rad: A = B = 0 and shins vertical (C = 90 deg)."""
        q = np.zeros(18)
        q[2::3] = 0.5 * math.pi
        return q


def parameter_specs() -> tuple[ParameterSpec, ...]:
    """Names, units and ranges of the 37 parameters (paper eq. 11), genes in [-1, 1]."""
    specs = [ParameterSpec("rho", "1", RHO_LOW, RHO_HIGH)]
    for index in EVOLVED_JOINTS:
        joint = JOINT_NAMES[index]
        specs += [
            ParameterSpec(f"{joint}.offset", "joint range", -1.0, 1.0),
            ParameterSpec(f"{joint}.amplitude", "joint range", 0.0, 1.0),
            ParameterSpec(f"{joint}.phase", "cycle", 0.0, 1.0),
        ]
    return tuple(specs)


class GaitTable:
    """Primitives in physical units, ready to give joint targets at any time.

    Args:
        genes: ``(n, 37)`` or ``(37,)`` genes in [-1, 1] (clipped).
        geometry: supplies the joint limits and omega.

    """

    def __init__(self, genes: np.ndarray, geometry: HexapodGeometry | None = None):
        g = np.clip(np.atleast_2d(np.asarray(genes, dtype=np.float64)), -1.0, 1.0)
        if g.shape[1] != N_PARAMETERS:
            raise ValueError(f"hexapod primitives have {N_PARAMETERS} genes, got {g.shape[1]}")
        self.geometry = geometry or HexapodGeometry()
        unit = 0.5 * (g + 1.0)  # [-1, 1] -> [0, 1]
        self.rho = RHO_LOW + unit[:, 0] * (RHO_HIGH - RHO_LOW)  # (n,)
        self.offset = g[:, 1::3]  # (n, 12) joint-range units
        self.amplitude = unit[:, 2::3]  # (n, 12)
        self.phase = unit[:, 3::3]  # (n, 12) cycles
        self.limits = self.geometry.evolved_limits()

    def __len__(self) -> int:
        return len(self.rho)

    def evolved_targets(self, t: float | np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """Eq. 10 targets (rad) of the 12 evolved joints at time ``t`` (s).

        Args:
            t: scalar, or ``(m,)`` times (one per selected row).
            rows: which primitives (default: all).

        Returns:
            ``(m, 12)`` rad.

        """
        sel = slice(None) if rows is None else rows
        t = np.asarray(t, dtype=np.float64)
        t_col = t[:, None] if t.ndim else t
        wave = np.sin(2.0 * math.pi * (t_col * self.geometry.frequency + self.phase[sel]))
        p = self.offset[sel] + self.amplitude[sel] * np.tanh(self.rho[sel][:, None] * wave)
        return np.clip(p, -1.0, 1.0) * self.limits

    def joint_targets(self, t: float | np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """All 18 joint targets (rad) at time ``t`` (s), ``C = -B + 90 deg``; ``(m, 18)``."""
        return full_pose(self.evolved_targets(t, rows))


def gait_step_times(first_step: int, steps: int, dt: float) -> np.ndarray:
    """Gait times (s) of physics steps ``first_step, first_step + 1, ...``: ``n * dt``.

    The simulation and the onboard executor both count whole steps since the gait began
    and multiply once, so they sample eq. 10 at bit-identical times.
    """
    return (first_step + np.arange(steps)) * dt


def full_pose(evolved: np.ndarray) -> np.ndarray:
    """``(m, 18)`` joint targets from ``(m, 12)`` A/B targets: each shin kept vertical."""
    evolved = np.atleast_2d(evolved)
    q = np.empty((evolved.shape[0], 18))
    q[:, 0::3] = evolved[:, 0::2]
    q[:, 1::3] = evolved[:, 1::2]
    q[:, 2::3] = 0.5 * math.pi - evolved[:, 1::2]
    return q


def mirror_genes(genes: np.ndarray) -> np.ndarray:
    """The left-right mirror image of primitives: left and right legs swap parameters.

    With A positive forward and B positive down on both sides (module docstring), the
    mirrored robot runs the mirrored gait and its displacement ``(x, y)`` becomes
    ``(x, -y)``, its heading ``-heading``.
    """
    g = np.array(genes, dtype=np.float64, copy=True)
    joints = g[..., 1:].reshape(*g.shape[:-1], 6, 6)  # (..., leg, A/B x offset/amp/phase)
    g[..., 1:] = joints[..., [3, 4, 5, 0, 1, 2], :].reshape(*g.shape[:-1], 36)
    return g
