"""A URDF file read as plain data, checked, and turned Z-up (docs/legged.md, "From a URDF").

This module reads what :mod:`sim_bridge.legged.urdf_reader` needs that PyBullet does not
report faithfully: each link's declared inertia (PyBullet substitutes a default for a zero
one) and each joint's declared limits (a ``continuous`` joint has none). It also writes the
*turned copy* of a URDF that is not Z-up: the same robot with its root link's frame turned
so that its up axis is +z, which is how evorbc spawns a Y-up robot upright (the simulation
measures tilt and heading on the root link's frame, so the frame itself must be turned,
not only the body at spawn).

Units: m, rad, kg, kg m^2. Frames: URDF link frames; ``rpy`` is fixed-axis roll, pitch,
yaw, as in URDF.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from evorbc_ros.config import ConfigError

#: Joint types that move (a ``continuous`` joint is a revolute joint without limits).
MOVABLE = ("revolute", "continuous", "prismatic")


class UrdfError(ConfigError):
    """A URDF evorbc cannot use; the one-line message says what to set."""


@dataclass(frozen=True)
class UrdfJoint:
    """One ``<joint>`` of a URDF (limits in rad; None when the URDF gives none)."""

    name: str
    type: str
    parent: str
    child: str
    lower: float | None
    upper: float | None
    effort: float | None  # N m
    velocity: float | None  # rad/s

    @property
    def movable(self) -> bool:
        """Whether the joint moves (revolute, continuous or prismatic)."""
        return self.type in MOVABLE


@dataclass(frozen=True)
class UrdfLink:
    """One ``<link>``: its mass (kg) and inertia (kg m^2; zeros when absent)."""

    name: str
    mass: float
    inertia: tuple[float, ...]  # ixx, iyy, izz, ixy, ixz, iyz

    def inertia_problem(self) -> str | None:
        """Why PyBullet would not take the inertia (it zeroes a bad one), or None."""
        ixx, iyy, izz, ixy, ixz, iyz = self.inertia
        if self.mass <= 0.0:
            return None
        if min(ixx, iyy, izz) <= 0.0:
            return "zero"
        tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        a, b, c = np.linalg.eigvalsh(tensor)
        # A rigid body's principal moments are positive and each at most the sum of the
        # other two (the triangle inequality).
        if a <= 0.0 or c > (a + b) * (1.0 + 1e-9):
            return "not physical"
        return None


@dataclass(frozen=True)
class UrdfModel:
    """A URDF's links and joints, in file order."""

    path: Path
    name: str
    links: dict[str, UrdfLink]
    joints: dict[str, UrdfJoint]

    @property
    def root(self) -> str:
        """The root link: the one no joint has as its child."""
        children = {j.child for j in self.joints.values()}
        roots = [name for name in self.links if name not in children]
        return roots[0]


def _number(element, attribute: str, default: float | None, where: str) -> float | None:
    text = element.get(attribute) if element is not None else None
    if text is None:
        return default
    try:
        return float(text)
    except ValueError:
        raise UrdfError(f"{where}: {attribute}={text!r} is not a number") from None


def read_urdf(path: str | os.PathLike) -> UrdfModel:
    """Read the links and joints of the URDF at ``path``.

    Raises:
        UrdfError: one line naming the file: unreadable, not a URDF, or a tree that is not
            one (no root link, or several).

    """
    path = Path(path)
    try:
        tree = ET.parse(path)
    except OSError as e:
        raise UrdfError(f"{path}: cannot read the URDF ({e.strerror})") from None
    except ET.ParseError as e:
        raise UrdfError(f"{path}: not a readable URDF (XML error: {e})") from None
    robot = tree.getroot()
    if robot.tag != "robot":
        raise UrdfError(f"{path}: not a URDF (its top element is <{robot.tag}>, not <robot>)")
    links = {}
    for element in robot.findall("link"):
        name = element.get("name")
        where = f"{path}: link {name!r}"
        inertial = element.find("inertial")
        mass = _number(inertial.find("mass") if inertial is not None else None, "value", 0.0, where)
        inertia = inertial.find("inertia") if inertial is not None else None
        keys = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
        links[name] = UrdfLink(name, mass, tuple(_number(inertia, k, 0.0, where) for k in keys))
    joints = {}
    for element in robot.findall("joint"):  # top level only: <transmission> has <joint>s too
        name = element.get("name")
        where = f"{path}: joint {name!r}"
        parent, child = element.find("parent"), element.find("child")
        if parent is None or child is None:
            raise UrdfError(f"{where}: expected a <parent> and a <child> link")
        limit = element.find("limit")
        kind = element.get("type", "")
        lower = _number(limit, "lower", None, where) if kind != "continuous" else None
        upper = _number(limit, "upper", None, where) if kind != "continuous" else None
        joints[name] = UrdfJoint(
            name,
            kind,
            parent.get("link"),
            child.get("link"),
            lower,
            upper,
            _number(limit, "effort", None, where),
            _number(limit, "velocity", None, where),
        )
    if not links:
        raise UrdfError(f"{path}: not a usable URDF (it has no <link>)")
    children = {j.child for j in joints.values()}
    roots = [name for name in links if name not in children]
    if len(roots) != 1:
        raise UrdfError(f"{path}: not a usable URDF ({len(roots)} root links, expected one)")
    return UrdfModel(path, robot.get("name", path.stem), links, joints)


def check_inertias(model: UrdfModel, links: list[str]) -> None:
    """Refuse links with mass but no inertia.

    PyBullet would invent one, and evorbc loads the URDF's own inertias
    (``URDF_USE_INERTIA_FROM_FILE``).

    Raises:
        UrdfError: one line naming the file and the first such links.

    """
    problems = {name: model.links[name].inertia_problem() for name in links}
    for kind in ("zero", "not physical"):
        bad = [name for name, problem in problems.items() if problem == kind]
        if not bad:
            continue
        shown = ", ".join(bad[:4]) + (f" and {len(bad) - 4} more" if len(bad) > 4 else "")
        what = "zero inertias" if kind == "zero" else "inertias no rigid body has"
        raise UrdfError(
            f"{model.path}: {what} ({shown}): set each link's <inertia> (kg m^2) to its "
            "real values (positive principal moments, each at most the sum of the others)"
        )


# -- the turned copy ----------------------------------------------------------------------


def _rotation_rpy(rpy) -> np.ndarray:
    """``(3, 3)`` rotation of URDF fixed-axis ``rpy`` (rad): Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = (
        math.cos(r),
        math.sin(r),
        math.cos(p),
        math.sin(p),
        math.cos(y),
        math.sin(y),
    )
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def rpy_of(rotation: np.ndarray) -> tuple[float, float, float]:
    """URDF ``rpy`` (rad) of a ``(3, 3)`` rotation (the inverse of :func:`_rotation_rpy`)."""
    m = np.asarray(rotation)
    pitch = math.asin(max(-1.0, min(1.0, -m[2, 0])))
    if abs(m[2, 0]) < 1.0 - 1e-12:
        roll = math.atan2(m[2, 1], m[2, 2])
        yaw = math.atan2(m[1, 0], m[0, 0])
    else:  # gimbal lock: put it all in yaw
        roll, yaw = 0.0, math.atan2(-m[0, 1], m[1, 1])
    return roll, pitch, yaw


def _vector(text: str | None) -> np.ndarray:
    return np.array([float(v) for v in (text or "0 0 0").split()], dtype=np.float64)


def _text(values) -> str:
    return " ".join(f"{float(v):.9g}" for v in values)


def _turn_origin(element, turn: np.ndarray) -> None:
    """Pre-multiply the ``<origin>`` of ``element`` by the rotation ``turn``."""
    origin = element.find("origin")
    if origin is None:
        origin = ET.SubElement(element, "origin")
    xyz = _vector(origin.get("xyz"))
    rotation = turn @ _rotation_rpy(_vector(origin.get("rpy")))
    origin.set("xyz", _text(turn @ xyz))
    origin.set("rpy", _text(rpy_of(rotation)))


def _turn_inertial(inertial, turn: np.ndarray) -> None:
    """Turn an ``<inertial>``, keeping its frame parallel to the link's.

    PyBullet reports the root link's pose as its inertial frame's, so that frame must end
    up Z-up as well.
    """
    origin = inertial.find("origin")
    xyz = _vector(origin.get("xyz") if origin is not None else None)
    rpy = _vector(origin.get("rpy") if origin is not None else None)
    inertia = inertial.find("inertia")
    if inertia is not None:
        keys = (("ixx", "ixy", "ixz"), ("ixy", "iyy", "iyz"), ("ixz", "iyz", "izz"))
        tensor = np.array([[float(inertia.get(k, 0.0)) for k in row] for row in keys])
        rotation = turn @ _rotation_rpy(rpy)
        turned = rotation @ tensor @ rotation.T
        for i, j, key in ((0, 0, "ixx"), (0, 1, "ixy"), (0, 2, "ixz"), (1, 1, "iyy")):
            inertia.set(key, f"{turned[i, j]:.9g}")
        inertia.set("iyz", f"{turned[1, 2]:.9g}")
        inertia.set("izz", f"{turned[2, 2]:.9g}")
    if origin is None:
        origin = ET.SubElement(inertial, "origin")
    origin.set("xyz", _text(turn @ xyz))
    origin.set("rpy", "0 0 0")


def turned_urdf_text(model: UrdfModel, turn: np.ndarray, note: str) -> str:
    """The URDF of ``model`` with its root link's frame turned by ``turn`` ``(3, 3)``.

    A vector ``v`` of the old root frame is ``turn @ v`` in the new one; every link but the
    root keeps its frame. Relative mesh file names become absolute (the copy lives
    elsewhere); ``note`` opens the file as an XML comment.
    """
    tree = ET.parse(model.path)
    robot = tree.getroot()
    folder = model.path.resolve().parent
    for mesh in robot.iter("mesh"):
        filename = mesh.get("filename", "")
        if filename and "://" not in filename and not os.path.isabs(filename):
            mesh.set("filename", str(folder / filename))
    root = model.root
    for link in robot.findall("link"):
        if link.get("name") != root:
            continue
        for shape in link.findall("visual") + link.findall("collision"):
            _turn_origin(shape, turn)
        for inertial in link.findall("inertial"):
            _turn_inertial(inertial, turn)
    for joint in robot.findall("joint"):
        parent = joint.find("parent")
        if parent is not None and parent.get("link") == root:
            _turn_origin(joint, turn)
    body = ET.tostring(robot, encoding="unicode")
    return f'<?xml version="1.0"?>\n<!-- {note} -->\n{body}\n'
