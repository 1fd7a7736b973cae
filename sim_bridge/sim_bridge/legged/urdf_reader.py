"""What a legged robot's URDF says about its gait design (docs/legged.md, "From a URDF").

:func:`read_legged_urdf` derives, from the URDF alone: the up axis and the turn that makes
the robot Z-up, the base and foot links, the legs (chains of movable joints from the base
to each foot) with their left/right mirrors, each joint's role (hip abduction, thigh,
knee) and limits, the standing pose, the foot positions in it, and the thigh/knee coupling
that keeps each foot under its hip as the knee bends (the A1's ``thigh = swing - knee /
2``, docs/a1.md; the hexapod's ``C = 90 deg - B`` is the same idea for its shin).

The coupling is measured, not assumed: for knee angles across the standing range, the
forward kinematics (PyBullet, DIRECT) finds the thigh angle that puts the foot straight
below the thigh joint, and a straight line is fitted through them. For a two-link leg with
segments of equal length it is exactly ``thigh = c - knee / 2``; the fit's largest error
is reported.

Frames: the *robot frame* is the root link's URDF frame turned Z-up: x forward, y left,
z up (REP 103). A *sagittal* angle is a rotation about the robot's +y axis, positive
moving a foot below the joint backwards. Units: m, rad.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sim_bridge.legged.urdf_model import UrdfError, UrdfModel, check_inertias, read_urdf
from sim_bridge.quiet_pybullet import p

#: Axis names of the robot and URDF frames.
AXES = "xyz"
#: The standing height as a share of the straight leg (hip to foot): the A1's shipped
#: stance (0.249 m of 0.4 m at knee -103 deg, docs/a1.md).
STANCE = 0.62
#: Half the knee's range about its standing angle and half the swing's: the A1's shipped
#: ranges (docs/a1.md, "Gait design"). Angles do not scale with size.
KNEE_HALF_RANGE = math.radians(15.0)
SWING_HALF_RANGE = math.radians(25.0)
#: Leg names that say front or rear (FL, lf, front_left ... / RR, lh, hind_left ...).
_FRONT = re.compile(r"(^|[_\-])(f[lr]?|[lr]f|front|fore)([_\-]|$)", re.IGNORECASE)
_REAR = re.compile(r"(^|[_\-])(r[lr]|[lr][rh]|h[lr]|rear|hind|back)([_\-]|$)", re.IGNORECASE)
_FOOT_NAME = re.compile(r"toe|foot|feet|tip", re.IGNORECASE)


@dataclass
class Leg:
    """One leg: joints from the base outwards and what they measure (robot frame)."""

    name: str  # the joints' common prefix (FL) or the foot link's name
    joints: tuple[str, ...]  # movable joints, base to foot
    roles: tuple[str, ...]  # "abduction", "thigh", "knee" per joint
    foot: str  # the foot link
    limits: tuple[tuple[float | None, float | None], ...]  # rad per joint (None: none)
    hip: np.ndarray  # (3,) m, the thigh joint's position in the zero pose
    side: str = ""  # "left" or "right" (the hip's lateral offset)
    mirror: str = ""  # the leg that mirrors this one
    signs: dict[str, int] = field(default_factory=dict)  # role -> +1: the joint turns about +y
    segments: tuple[float, float] = (0.0, 0.0)  # m, thigh and shank (in the sagittal plane)
    abduction: float = 0.0  # rad, held
    knee_stand: float = 0.0  # rad, joint angle
    thigh_stand: float = 0.0  # rad, joint angle
    coupling: tuple[float, float] = (0.0, 0.0)  # thigh = c0 + c1 knee (rad, joint angles)
    coupling_error: float = 0.0  # rad, the fit's largest error over the knee range
    knee_range: tuple[float, float] = (0.0, 0.0)  # rad, joint angles
    swing_half: float = SWING_HALF_RANGE  # rad
    foot_stand: np.ndarray = field(default_factory=lambda: np.zeros(3))  # m, robot frame
    notes: list[str] = field(default_factory=list)


@dataclass
class DerivedRobot:
    """Everything :func:`read_legged_urdf` derived, with how (``notes``)."""

    model: UrdfModel
    up: str  # the URDF's up axis: "x", "y" or "z" (with its sign, "-y" ...)
    up_detected: str  # what the legs said
    turn: np.ndarray  # (3, 3): a root-frame vector v is turn @ v in the robot frame
    turn_given: str  # how the turn was decided
    base: str
    legs: list[Leg]
    mass: float  # kg, the whole robot
    stance: float

    @property
    def turned(self) -> bool:
        """Whether the URDF's root frame is not already the robot frame."""
        return not np.allclose(self.turn, np.eye(3))


@contextlib.contextmanager
def _quiet_stderr():
    """Silence PyBullet's C-level warnings (missing meshes, materials) while loading."""
    import sys

    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)


class _Kinematics:
    """The URDF in a PyBullet DIRECT client, for forward kinematics in the root frame."""

    def __init__(self, path: Path) -> None:
        self.client = p.connect(p.DIRECT)
        try:
            with _quiet_stderr():
                self.body = p.loadURDF(str(path), physicsClientId=self.client)
        except p.error:
            p.disconnect(self.client)
            raise UrdfError(f"{path}: PyBullet cannot load the URDF (a missing mesh?)") from None
        c = self.client
        n = p.getNumJoints(self.body, physicsClientId=c)
        self.infos = [p.getJointInfo(self.body, j, physicsClientId=c) for j in range(n)]
        self.index = {info[1].decode(): info[0] for info in self.infos}
        self.link_index = {info[12].decode(): info[0] for info in self.infos}
        # The root link's URDF frame: its centre-of-mass pose less its inertial offset.
        com, orn = p.getBasePositionAndOrientation(self.body, physicsClientId=c)
        local = p.getDynamicsInfo(self.body, -1, physicsClientId=c)[3:5]
        inv_pos, inv_orn = p.invertTransform(local[0], local[1])
        pos, orn = p.multiplyTransforms(com, orn, inv_pos, inv_orn)
        self.origin = np.array(pos)
        self.rotation = np.array(p.getMatrixFromQuaternion(orn)).reshape(3, 3)
        self.base_com = self.rotation.T @ (np.array(com) - self.origin)

    def set(self, angles: dict[str, float]) -> None:
        """Put joints (by name) at angles (rad)."""
        for name, q in angles.items():
            p.resetJointState(self.body, self.index[name], q, physicsClientId=self.client)

    def link_frame(self, link: str) -> tuple[np.ndarray, np.ndarray]:
        """``((3,) position, (3, 3) rotation)`` of a link's URDF frame in the root frame."""
        state = p.getLinkState(
            self.body,
            self.link_index[link],
            computeForwardKinematics=1,
            physicsClientId=self.client,
        )
        rotation = np.array(p.getMatrixFromQuaternion(state[5])).reshape(3, 3)
        return self.rotation.T @ (np.array(state[4]) - self.origin), self.rotation.T @ rotation

    def joint_axis(self, joint: str) -> np.ndarray:
        """``(3,)`` the joint's axis in the root frame (a joint's frame is its child's)."""
        info = self.infos[self.index[joint]]
        _, rotation = self.link_frame(info[12].decode())
        return rotation @ np.array(info[13])

    def joint_position(self, joint: str) -> np.ndarray:
        """``(3,)`` m, a point on the joint's axis (its frame's origin), root frame."""
        return self.link_frame(self.infos[self.index[joint]][12].decode())[0]

    def close(self) -> None:
        """Disconnect."""
        p.disconnect(self.client)


def _chains(model: UrdfModel) -> list[tuple[list[str], str]]:
    """``(movable joints from the root, foot link)`` per leg.

    A foot is a leaf link below at least two movable joints: per first movable joint (a
    leg), the deepest, then one named toe/foot. A leaf that moves itself is no foot unless
    so named; a leg without a foot gives ``""``.
    """
    children: dict[str, list] = {}
    for joint in model.joints.values():
        children.setdefault(joint.parent, []).append(joint)
    found: dict[str, tuple[list[str], str, bool]] = {}
    stack = [(model.root, [], False)]
    while stack:
        link, movable, last_moved = stack.pop()
        below = children.get(link, [])
        if not below and len(movable) >= 2:
            foot_like = not last_moved or bool(_FOOT_NAME.search(link))
            key = movable[0]
            best = found.get(key)
            rank = (len(movable), foot_like, bool(_FOOT_NAME.search(link)))
            if best is None or rank > (len(best[0]), best[2], bool(_FOOT_NAME.search(best[1]))):
                found[key] = (movable, link, foot_like)
        for joint in below:
            moved = joint.movable
            stack.append((joint.child, [*movable, joint.name] if moved else movable, moved))
    return [(m, link) for m, link, foot_like in found.values() if foot_like] or [
        (m, "") for m, _, _ in found.values()
    ]


def _leg_name(joints: list[str], foot: str) -> str:
    prefix = joints[0]
    for other in joints[1:]:  # the names' common start, letter by letter
        while not other.startswith(prefix):
            prefix = prefix[:-1]
    cut = max(prefix.rfind("_"), prefix.rfind("-"))
    name = prefix[:cut] if cut > 0 else ""
    return name if name else foot


def _axis_name(vector: np.ndarray) -> str:
    k = int(np.argmax(np.abs(vector)))
    return ("-" if vector[k] < 0 else "") + AXES[k]


def _unit(axis: str) -> np.ndarray:
    v = np.zeros(3)
    v[AXES.index(axis[-1])] = -1.0 if axis.startswith("-") else 1.0
    return v


def read_legged_urdf(
    path: str | os.PathLike,
    up: str | None = None,
    turn_rpy: tuple[float, float, float] | None = None,
    stance: float = STANCE,
) -> DerivedRobot:
    """Derive a legged robot's design from its URDF (module docstring).

    Args:
        path: the URDF.
        up: the URDF's up axis (``"z"``, ``"y"``, ``"x"``, optionally ``"-y"`` ...), or
            None: Z-up, refused when the legs say otherwise.
        turn_rpy: the turn (rad, URDF roll, pitch, yaw) that makes the robot Z-up and
            facing +x; overrides ``up``.
        stance: the standing height as a share of the straight leg.

    Raises:
        UrdfError: one line saying what to set (the module's refusals).

    """
    model = read_urdf(path)
    chains = _chains(model)
    if not chains or not all(foot for _, foot in chains):
        tips = ", ".join(sorted({model.joints[m[-1]].child for m, _ in chains})) or "none"
        raise UrdfError(
            f"{model.path}: no foot links found (legs end at moving links: {tips}); add a "
            "fixed link named *_toe or *_foot at each foot's contact point"
        )
    kin = _Kinematics(model.path)
    try:
        return _derive(model, kin, chains, up, turn_rpy, stance)
    finally:
        kin.close()


def _derive(model, kin, chains, up, turn_rpy, stance) -> DerivedRobot:
    kin.set({j: 0.0 for j in kin.index})
    feet_root = np.array([kin.link_frame(foot)[0] for _, foot in chains])
    detected = _axis_name(-(feet_root.mean(axis=0) - kin.base_com))
    sibling = model.path.with_name(model.path.stem + "_zup.urdf")
    if turn_rpy is not None:
        from sim_bridge.legged.urdf_model import _rotation_rpy

        turn = _rotation_rpy(turn_rpy)
        given = "given by --turn"
        up_axis = _axis_name(turn.T @ np.array([0.0, 0.0, 1.0]))
    else:
        up_axis = up if up is not None else "z"
        if up is None and detected != "z":
            also = f", or use {sibling.name} beside it" if sibling.is_file() else ""
            raise UrdfError(
                f"{model.path}: the URDF is {detected.lstrip('-').upper()}-up (its feet lie "
                f"along {_axis_name(-_unit(detected))} of {model.root!r}) and no turn was "
                f"given: pass --up {detected}{also}"
            )
        turn, given = _turn_for(up_axis, feet_root, chains, up)
    check_inertias(model, list(model.links))
    legs = [_leg(model, kin, turn, movable, foot) for movable, foot in chains]
    _pair_mirrors(model, legs)
    for leg in legs:
        _stand(model, kin, turn, leg, stance)
    _share_mirrors(legs)
    # Front to back, left before right (the A1's order: FL, FR, RL, RR).
    legs.sort(key=lambda leg: (-round(float(leg.hip[0]), 2), leg.side != "left", leg.name))
    mass = sum(link.mass for link in model.links.values())
    return DerivedRobot(model, up_axis, detected, turn, given, model.root, legs, mass, stance)


def _turn_for(up: str, feet: np.ndarray, chains, given: str | None):
    """The turn making ``up`` +z, and how it was decided.

    Forward is along the feet's longest spread, front legs (by name) ahead. A Z-up URDF
    keeps its own x forward (REP 103).
    """
    up_vector = _unit(up)
    if np.allclose(up_vector, [0.0, 0.0, 1.0]):
        how = "given by --up z" if given else "the URDF's own: its feet lie along -z"
        return np.eye(3), how
    spread = np.ptp(feet, axis=0)
    spread[AXES.index(up[-1])] = -1.0
    k = int(np.argmax(spread))
    forward = np.zeros(3)
    forward[k] = 1.0
    front = [f[k] for (m, _), f in zip(chains, feet, strict=True) if _FRONT.search(m[0])]
    rear = [f[k] for (m, _), f in zip(chains, feet, strict=True) if _REAR.search(m[0])]
    how = f"given by --up {up}; forward +{AXES[k]}, the feet's longest spread"
    if front and rear and np.mean(front) < np.mean(rear):
        forward = -forward
        how = f"given by --up {up}; forward -{AXES[k]}, the feet's longest spread, front legs ahead"
    elif front and rear:
        how += ", front legs ahead"
    left = np.cross(up_vector, forward)
    return np.array([forward, left, up_vector]), how


def _leg(
    model: UrdfModel, kin: _Kinematics, turn: np.ndarray, movable: list[str], foot: str
) -> Leg:
    roles = []
    axes = [turn @ kin.joint_axis(j) for j in movable]
    kinds = [_axis_name(a).lstrip("-") for a in axes]
    if kinds == ["x", "y", "y"]:
        roles = ["abduction", "thigh", "knee"]
    elif kinds == ["y", "y"]:
        roles = ["thigh", "knee"]
    else:
        about = {"x": "roll", "y": "pitch", "z": "yaw"}
        raise UrdfError(
            f"{model.path}: the leg to {foot!r} has joints turning about "
            f"{', '.join(about[k] for k in kinds)}; evorbc reads legs of a hip abduction "
            "(roll) then a thigh and a knee (pitch): write its settings by hand (docs/legged.md)"
        )
    thigh = movable[roles.index("thigh")]
    leg = Leg(
        name=_leg_name(movable, foot),
        joints=tuple(movable),
        roles=tuple(roles),
        foot=foot,
        limits=tuple((model.joints[j].lower, model.joints[j].upper) for j in movable),
        hip=turn @ kin.joint_position(thigh),
    )
    for role, axis in zip(roles, axes, strict=True):
        leg.signs[role] = 1 if (axis[1] if role != "abduction" else axis[0]) > 0 else -1
    leg.side = "left" if leg.hip[1] > 0 else "right"
    return leg


def _pair_mirrors(model: UrdfModel, legs: list[Leg]) -> None:
    """Each leg's mirror: the leg of the other side nearest its hip's mirror image."""
    for leg in legs:
        image = leg.hip * np.array([1.0, -1.0, 1.0])
        others = [o for o in legs if o.side != leg.side]
        if not others:
            raise UrdfError(f"{model.path}: every leg is on the {leg.side}: no left/right mirrors")
        mirror = min(others, key=lambda o: float(np.linalg.norm(o.hip - image)))
        leg.mirror = mirror.name
    for leg in legs:
        back = next(o for o in legs if o.name == leg.mirror)
        if back.mirror != leg.name:
            raise UrdfError(
                f"{model.path}: legs {leg.name} and {back.name} do not mirror each other "
                "(hips not symmetric about the x-z plane)"
            )


def _within(q: float, limits: tuple[float | None, float | None]) -> bool:
    low, high = limits
    return (low is None or q >= low - 1e-9) and (high is None or q <= high + 1e-9)


class _LegPlane:
    """One leg's thigh and knee in the robot frame (turned Z-up), the other joints held."""

    def __init__(self, kin: _Kinematics, turn: np.ndarray, leg: Leg, thigh: str, knee: str):
        self.kin, self.turn, self.leg, self.thigh, self.knee = kin, turn, leg, thigh, knee
        kin.set({thigh: 0.0, knee: 0.0})
        self.hip = turn @ kin.joint_position(thigh)  # m, robot frame
        self.knee_point = turn @ kin.joint_position(knee)
        self.foot0 = self.foot_at(0.0, 0.0)

    def foot_at(self, t: float, k: float) -> np.ndarray:
        """The foot's position (m, robot frame) at thigh ``t`` and knee ``k`` (rad)."""
        self.kin.set({self.thigh: t, self.knee: k})
        return self.turn @ self.kin.link_frame(self.leg.foot)[0]

    def under(self, k: float) -> float | None:
        """The thigh angle (rad) putting the foot straight below the hip, knee behind."""
        hip = self.hip
        grid = np.linspace(-math.pi, math.pi, 73)  # 5 deg
        values = [self.foot_at(t, k)[0] - hip[0] for t in grid]
        best = None
        for a, b, fa, fb in zip(grid[:-1], grid[1:], values[:-1], values[1:], strict=True):
            if fa == 0.0 or fa * fb < 0.0:
                for _ in range(40):  # bisection to below 1e-12 rad
                    mid = 0.5 * (a + b)
                    fm = self.foot_at(mid, k)[0] - hip[0]
                    a, b, fa = (a, mid, fa) if fa * fm <= 0.0 else (mid, b, fm)
                t = 0.5 * (a + b)
                below = self.foot_at(t, k)[2] < hip[2]
                self.kin.set({self.thigh: t, self.knee: k})
                behind = (self.turn @ self.kin.joint_position(self.knee))[0] < hip[0] - 1e-6
                if below and behind and (best is None or abs(t) < abs(best)):
                    best = t
        return best

    def height(self, k: float) -> float:
        """m: the hip's height over the foot kept under it at knee ``k``; -inf if none."""
        t = self.under(k)
        return -math.inf if t is None else float(self.hip[2] - self.foot_at(t, k)[2])


def _stand(model: UrdfModel, kin: _Kinematics, turn: np.ndarray, leg: Leg, stance: float) -> None:
    """The leg's standing pose and the thigh/knee coupling keeping its foot under its hip."""
    names = dict(zip(leg.roles, leg.joints, strict=True))
    limits = dict(zip(leg.roles, leg.limits, strict=True))
    if "abduction" in names:
        _hold_abduction(kin, leg, names["abduction"], limits["abduction"])
    plane = _LegPlane(kin, turn, leg, names["thigh"], names["knee"])
    leg.segments = (
        float(np.hypot(*(plane.knee_point - plane.hip)[[0, 2]])),
        float(np.hypot(*(plane.foot0 - plane.knee_point)[[0, 2]])),
    )
    k0 = _standing_knee(model, plane, limits["knee"], stance * sum(leg.segments))
    c0, c1, k_low, k_high = _knee_range_and_coupling(model, plane, limits["knee"], k0)
    leg.thigh_stand = float(c0 + c1 * k0)
    leg.foot_stand = plane.foot_at(leg.thigh_stand, k0)
    _swing_room(leg, limits["thigh"], [c0 + c1 * k for k in (k_low, k_high)])
    kin.set({names["thigh"]: 0.0, names["knee"]: 0.0})


def _hold_abduction(kin: _Kinematics, leg: Leg, joint: str, limits) -> None:
    """Hold the abduction at 0 rad, or at its limits' middle when 0 is outside them."""
    low, high = limits
    leg.abduction = 0.0 if _within(0.0, limits) else 0.5 * (low + high)
    kin.set({joint: leg.abduction})
    if leg.abduction:
        leg.notes.append("abduction: 0 is outside its limits; held at their middle")


def _standing_knee(model: UrdfModel, plane: _LegPlane, limits, target: float) -> float:
    """The knee angle (rad) at which the foot under the hip is ``target`` m below it."""
    leg = plane.leg
    low, high = limits
    knees = np.linspace(
        -math.pi + 0.01 if low is None else low, math.pi - 0.01 if high is None else high, 181
    )
    heights = np.array([plane.height(k) for k in knees])
    crossing = [
        (a, b)
        for a, b, ha, hb in zip(knees[:-1], knees[1:], heights[:-1], heights[1:], strict=True)
        if np.isfinite(ha) and np.isfinite(hb) and (ha - target) * (hb - target) <= 0.0
    ]
    if not crossing:
        reachable = heights[np.isfinite(heights)]
        if not len(reachable):
            raise UrdfError(
                f"{model.path}: leg {leg.name}: no knee angle puts its foot below its hip "
                "with the knee behind; write its settings by hand (docs/legged.md)"
            )
        leg.notes.append(f"knee: the stance height {target:.3f} m is out of reach; nearest kept")
        gap = np.where(np.isfinite(heights), np.abs(heights - target), np.inf)
        return float(knees[int(np.argmin(gap))])
    # The bend nearest straight that reaches the height (fold the knee least).
    a, b = min(crossing, key=lambda ab: abs(ab[0] + ab[1]))
    ha = plane.height(a) - target
    for _ in range(40):
        mid = 0.5 * (a + b)
        hm = plane.height(mid) - target
        a, b, ha = (a, mid, ha) if ha * hm <= 0.0 else (mid, b, hm)
    return 0.5 * (a + b)


def _knee_range_and_coupling(model: UrdfModel, plane: _LegPlane, limits, k0: float):
    """The knee's range about ``k0`` and the line thigh = c0 + c1 knee keeping the foot under.

    Returns ``(c0, c1, k_low, k_high)``, rad; sets the leg's knee and coupling fields.
    """
    leg = plane.leg
    low, high = limits
    leg.knee_stand = k0
    half = KNEE_HALF_RANGE
    k_low = max(k0 - half, low if low is not None else -math.inf)
    k_high = min(k0 + half, high if high is not None else math.inf)
    if k_high - k_low < 2.0 * half - 1e-9:
        leg.notes.append("knee: its range is cut by the URDF's limits")
    leg.knee_range = (k_low, k_high)
    samples = np.linspace(k_low, k_high, 31)
    thighs = np.array([plane.under(k) for k in samples], dtype=float)
    if np.isnan(thighs).any():
        raise UrdfError(
            f"{model.path}: leg {leg.name}: over the knee's standing range its foot cannot "
            "stay under its hip; write its settings by hand (docs/legged.md)"
        )
    c1, c0 = np.polyfit(samples, thighs, 1)
    leg.coupling = (float(c0), float(c1))
    leg.coupling_error = float(np.max(np.abs(c0 + c1 * samples - thighs)))
    return c0, c1, k_low, k_high


def _swing_room(leg: Leg, limits, thighs: list[float]) -> None:
    """The swing's half range (rad): the swing adds to the thigh, whose limits it keeps.

    ``thighs``: the coupled thigh angle (rad) at each end of the knee's range.
    """
    t_low, t_high = limits
    room = [SWING_HALF_RANGE]
    for t in thighs:
        if t_low is not None:
            room.append(t - t_low)
        if t_high is not None:
            room.append(t_high - t)
    leg.swing_half = max(0.0, min(room))
    if leg.swing_half < SWING_HALF_RANGE:
        leg.notes.append("swing: its range is cut by the thigh's limits")


def _share_mirrors(legs: list[Leg]) -> None:
    """Give mirror pairs the left leg's values: mirror oscillators need mirrored ranges.

    Raises:
        UrdfError: the pair's geometry differs by more than 0.5 deg.

    """
    by_name = {leg.name: leg for leg in legs}
    for leg in legs:
        if leg.side != "right":
            continue
        left = by_name[leg.mirror]
        differs = max(
            abs(left.knee_stand * left.signs["knee"] - leg.knee_stand * leg.signs["knee"]),
            abs(left.swing_half - leg.swing_half),
        )
        if differs > math.radians(0.5):
            leg.notes.append(f"mirror: differs from {left.name} by {math.degrees(differs):.2f} deg")
        leg.swing_half = left.swing_half
        flip = left.signs["knee"] * leg.signs["knee"]
        lo, hi = (left.knee_range[0] * flip, left.knee_range[1] * flip)
        leg.knee_range = (min(lo, hi), max(lo, hi))
