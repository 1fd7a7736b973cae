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

import functools
import math
from dataclasses import dataclass

import numpy as np

# RHO_LOW, RHO_HIGH and gait_step_times are the hexapod's as well as every legged robot's.
from evorbc_ros.robots.legged import (  # noqa: F401
    RHO_HIGH,
    RHO_LOW,
    Gait,
    JointDrive,
    LeggedGaitTable,
    Oscillator,
    gait_step_times,
)
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


@functools.lru_cache(maxsize=8)
def hexapod_gait(geometry: HexapodGeometry | None = None) -> Gait:
    """The hexapod as a legged robot's gait (:mod:`evorbc_ros.robots.legged`).

    Oscillators ``A1, B1, ..., A6, B6`` (named after the joints they drive) over
    ``[-limit, limit]``; each drives its joint, and ``C = 90 deg - B`` keeps the shin
    vertical. Left and right legs mirror each other with the same signs (module docstring).
    ``config/robots/hexapod.yaml`` describes the same gait (a test keeps them equal).
    """
    g = geometry or HexapodGeometry()
    limits = (g.coxa_limit, g.femur_limit)
    oscillators, joints = [], []
    for k, leg in enumerate(LEG_NAMES):
        mirror_leg = LEG_NAMES[(k + 3) % 6]
        for i in (0, 1):
            name, mirror = f"{leg}_{LEG_JOINTS[i]}", f"{mirror_leg}_{LEG_JOINTS[i]}"
            oscillators.append(Oscillator(name, -limits[i], limits[i], mirror, 1.0))
        a, b = 2 * k, 2 * k + 1
        joints += [
            JointDrive(f"{leg}_coxa", 0.0, ((a, 1.0),)),
            JointDrive(f"{leg}_femur", 0.0, ((b, 1.0),)),
            JointDrive(f"{leg}_tibia", 0.5 * math.pi, ((b, -1.0),)),
        ]
    return Gait(tuple(oscillators), tuple(joints), g.frequency)


def parameter_specs() -> tuple[ParameterSpec, ...]:
    """Names, units and ranges of the 37 parameters (paper eq. 11), genes in [-1, 1]."""
    return hexapod_gait().parameter_specs()


class GaitTable(LeggedGaitTable):
    """Primitives in physical units, ready to give joint targets at any time.

    Args:
        genes: ``(n, 37)`` or ``(37,)`` genes in [-1, 1] (clipped).
        geometry: supplies the joint limits and omega.

    """

    def __init__(self, genes: np.ndarray, geometry: HexapodGeometry | None = None):
        self.geometry = geometry or HexapodGeometry()
        super().__init__(genes, hexapod_gait(self.geometry), HEXAPOD)


def mirror_genes(genes: np.ndarray) -> np.ndarray:
    """The left-right mirror image of primitives: left and right legs swap parameters.

    With A positive forward and B positive down on both sides (module docstring), the
    mirrored robot runs the mirrored gait and its displacement ``(x, y)`` becomes
    ``(x, -y)``, its heading ``-heading``.
    """
    return hexapod_gait().mirror_genes(genes)
