"""A URDF of the hexapod, generated from :class:`~evorbc_ros.robots.hexapod.HexapodGeometry`.

Links: ``base`` (a box), and per leg ``<leg>_coxa``, ``<leg>_femur``, ``<leg>_tibia``
(rods, inertia only) ending in a foot sphere. Only the body box and the six foot spheres
collide: the shin is kept vertical under the knee, so the feet are the outermost points
of the legs and walls meet either a foot or the body.

Joint frames: each leg frame has x along the leg's neutral direction (outwards), z up.
A turns about z (sign chosen so that positive swings the foot forward on both sides), B
and C turn about the leg frame's y, so positive angles lower the next segment's tip.
"""

from __future__ import annotations

import math
from xml.sax.saxutils import quoteattr

from evorbc_ros.robots.hexapod import JOINT_NAMES, LEG_NAMES, HexapodGeometry


def _f(value: float) -> str:
    return repr(float(value))


def _rod_inertia(mass: float, length: float, radius: float) -> str:
    # Solid cylinder along x (kg m^2).
    axial = 0.5 * mass * radius**2
    transverse = mass * (3.0 * radius**2 + length**2) / 12.0
    return (
        f'<inertia ixx="{_f(axial)}" iyy="{_f(transverse)}" izz="{_f(transverse)}" '
        'ixy="0" ixz="0" iyz="0"/>'
    )


def _box_inertia(mass: float, a: float, b: float, c: float) -> str:
    return (
        f'<inertia ixx="{_f(mass * (b * b + c * c) / 12)}" '
        f'iyy="{_f(mass * (a * a + c * c) / 12)}" izz="{_f(mass * (a * a + b * b) / 12)}" '
        'ixy="0" ixz="0" iyz="0"/>'
    )


def _rod_link(name: str, mass: float, length: float, g: HexapodGeometry, foot: bool) -> str:
    inertial = (
        f'<inertial><origin xyz="{_f(length / 2)} 0 0"/><mass value="{_f(mass)}"/>'
        f"{_rod_inertia(mass, length, g.segment_radius)}</inertial>"
    )
    visual = (
        f'<visual><origin xyz="{_f(length / 2)} 0 0" rpy="0 {_f(math.pi / 2)} 0"/>'
        f'<geometry><cylinder radius="{_f(g.segment_radius)}" length="{_f(length)}"/>'
        "</geometry></visual>"
    )
    collision = ""
    if foot:
        collision = (
            f'<collision><origin xyz="{_f(length)} 0 0"/>'
            f'<geometry><sphere radius="{_f(g.foot_radius)}"/></geometry></collision>'
        )
    return f"<link name={quoteattr(name)}>{inertial}{visual}{collision}</link>"


def _joint(name, parent, child, xyz, rpy, axis, low, high, effort, velocity) -> str:
    return (
        f'<joint name={quoteattr(name)} type="revolute">'
        f"<parent link={quoteattr(parent)}/><child link={quoteattr(child)}/>"
        f'<origin xyz="{" ".join(map(_f, xyz))}" rpy="{" ".join(map(_f, rpy))}"/>'
        f'<axis xyz="{" ".join(map(_f, axis))}"/>'
        f'<limit lower="{_f(low)}" upper="{_f(high)}" effort="{_f(effort)}" '
        f'velocity="{_f(velocity)}"/></joint>'
    )


def hexapod_urdf(geometry: HexapodGeometry | None = None) -> str:
    """The URDF text of the hexapod (joints in :data:`JOINT_NAMES` order)."""
    g = geometry or HexapodGeometry()
    parts = ['<?xml version="1.0"?>', '<robot name="evorbc_hexapod">']
    size = (g.body_length, g.body_width, g.body_height)
    parts.append(
        '<link name="base">'
        f'<inertial><origin xyz="0 0 0"/><mass value="{_f(g.body_mass)}"/>'
        f"{_box_inertia(g.body_mass, *size)}</inertial>"
        f'<visual><geometry><box size="{" ".join(map(_f, size))}"/></geometry></visual>'
        f'<collision><geometry><box size="{" ".join(map(_f, size))}"/></geometry></collision>'
        "</link>"
    )
    hips = g.hip_positions()
    v = g.max_joint_velocity
    for k, leg in enumerate(LEG_NAMES):
        a_name, b_name, c_name = JOINT_NAMES[3 * k : 3 * k + 3]
        coxa, femur, tibia = (f"{leg}_coxa_link", f"{leg}_femur_link", f"{leg}_tibia_link")
        parts.append(_rod_link(coxa, g.coxa_mass, g.coxa_length, g, foot=False))
        parts.append(_rod_link(femur, g.femur_mass, g.femur_length, g, foot=False))
        parts.append(_rod_link(tibia, g.tibia_mass, g.tibia_length, g, foot=True))
        # Left legs (y > 0) swing forward when turning clockwise seen from above.
        a_axis = (0.0, 0.0, -1.0) if leg.startswith("l") else (0.0, 0.0, 1.0)
        yaw = math.radians(g.leg_yaw_deg[k])
        parts.append(
            _joint(a_name, "base", coxa, (*hips[k], 0.0), (0.0, 0.0, yaw), a_axis,
                   -g.coxa_limit, g.coxa_limit, g.coxa_torque, v)
        )  # fmt: skip
        parts.append(
            _joint(b_name, coxa, femur, (g.coxa_length, 0.0, 0.0), (0.0, 0.0, 0.0),
                   (0.0, 1.0, 0.0), -g.femur_limit, g.femur_limit, g.femur_torque, v)
        )  # fmt: skip
        parts.append(
            _joint(c_name, femur, tibia, (g.femur_length, 0.0, 0.0), (0.0, 0.0, 0.0),
                   (0.0, 1.0, 0.0), 0.0, math.pi, g.tibia_torque, v)
        )  # fmt: skip
    parts.append("</robot>")
    return "\n".join(parts) + "\n"
