"""A legged robot with a damaged leg or side (docs/perturbations.md, "Legged robots").

Legs are found from the URDF: leg ``k`` is the chain of actuated joints from the robot's
``k``-th foot link up to the body; its *knee* is the actuated joint nearest the foot (the
hexapod's tibia joint, the A1's calf joint). A leg is on the left when its foot stands at
``y > 0`` in the body frame (REP 103) when the episode starts.

* ``leg_lost``: the leg's links are gone: they collide with nothing (ground, walls, the
  robot), keep 0.1 % of their mass and inertia (PyBullet needs a mass) and their servos
  give no torque.
* ``leg_limp``: the leg's servos give no torque; the leg hangs limp and drags.
* ``knee_locked``: the knee's target is held at the angle the knee has at the episode's
  start, whatever the gait asks (its servo holds it with its usual torque).
* ``weak_leg`` / ``weak_side``: the servos of the leg / of every leg on the side give the
  drawn share of their maximal torque.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from sim_bridge.damage import SIDES, DamageDraw, DamageSpec
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.quiet_pybullet import p


def leg_links(sim: LeggedSim) -> list[list[int]]:
    """Per foot link, in the settings' order: the links of its leg, foot first.

    PyBullet numbers a link like the joint that carries it; the walk ends at the body (-1).
    """
    legs = []
    for foot in sim.feet:
        leg, link = [], foot
        while link >= 0:
            leg.append(link)
            link = p.getJointInfo(sim.robot, link, physicsClientId=sim.client)[16]
        legs.append(leg)
    return legs


def leg_columns(sim: LeggedSim) -> list[list[int]]:
    """Per foot link: the joint columns of its leg (into ``sim.joints``), knee first."""
    column = {j: k for k, j in enumerate(sim.joints)}
    return [[column[link] for link in leg if link in column] for leg in leg_links(sim)]


def leg_sides(sim: LeggedSim) -> list[str]:
    """Per foot link: ``left`` or ``right`` of the body now (its y in the body frame)."""
    c = sim.client
    (bx, by, _), orn = p.getBasePositionAndOrientation(sim.robot, physicsClientId=c)
    yaw = p.getEulerFromQuaternion(orn)[2]
    sides = []
    for foot in sim.feet:
        fx, fy, _ = p.getLinkState(sim.robot, foot, physicsClientId=c)[0]
        y = -math.sin(yaw) * (fx - bx) + math.cos(yaw) * (fy - by)
        sides.append(SIDES[0] if y > 0.0 else SIDES[1])
    return sides


def _remove(sim: LeggedSim, links: list[int]) -> Callable[[], None]:
    """Take ``links`` out of the world; return what puts them back, bit for bit.

    Collision pairs are switched off (the ground, the walls, the robot's other links),
    not the links' collision groups: taking a link out of the broadphase and back reorders
    its pairs, so later episodes would differ. The mass and inertia shrink together
    (PyBullet recomputes the inertia from the shape when given the mass alone).
    """
    c, robot = sim.client, sim.robot
    others = [(robot, k) for k in range(-1, p.getNumJoints(robot, physicsClientId=c))]
    others = [(b, k) for b, k in others if k not in links]
    others += [(body, -1) for body in (sim.ground, *sim.walls)]
    info = [p.getDynamicsInfo(robot, k, physicsClientId=c) for k in links]

    def switch(enable: int) -> None:
        for k in links:
            for body, other in others:
                p.setCollisionFilterPair(robot, body, k, other, enable, physicsClientId=c)

    switch(0)
    for k, i in zip(links, info, strict=True):
        p.changeDynamics(
            robot, k, mass=i[0] * 1e-3, localInertiaDiagonal=[v * 1e-3 for v in i[2]],
            physicsClientId=c,
        )  # fmt: skip

    def restore() -> None:
        switch(1)
        for k, i in zip(links, info, strict=True):
            p.changeDynamics(robot, k, mass=i[0], localInertiaDiagonal=i[2], physicsClientId=c)

    return restore


def apply_damage(sim: LeggedSim, row: dict, torques: list[float]) -> Callable[[], None] | None:
    """Set ``sim.torques`` (from the nominal ``torques``) and ``sim.locked`` for ``row``.

    ``row``: a :meth:`~sim_bridge.damage.DamageDraw.row` dict. The caller puts the torques
    and locks back; a lost leg's links come back through the returned callable.
    """
    legs = leg_columns(sim)
    names = tuple(sim.settings.foot_links)
    draw = DamageDraw(
        DamageSpec(row["kind"], row["part"]),
        *([row[k]] for k in ("part_u", "level", "sign")),
    )
    kind = row["kind"]
    if kind == "leg_lost":
        # Its servos stop too: driving links of 0.1 % of their mass at full torque shakes
        # the solver.
        leg = draw.part(0, names)
        sim.torques = [0.0 if k in legs[leg] else t for k, t in enumerate(torques)]
        return _remove(sim, leg_links(sim)[leg])
    if kind == "weak_side":
        side = SIDES[draw.part(0, SIDES)]
        columns = [c for leg, s in zip(legs, leg_sides(sim), strict=True) if s == side for c in leg]
    else:
        columns = legs[draw.part(0, names)]
    if kind == "knee_locked":
        angles = sim.joint_states()[0]
        sim.locked = {columns[0]: float(angles[columns[0]])}
        return None
    share = 0.0 if kind == "leg_limp" else row["level"]
    sim.torques = [t * share if k in columns else t for k, t in enumerate(torques)]
    return None
