"""Perturbed worlds in a legged robot's PyBullet episode (docs/design.md section 21).

A perturbed world (one :meth:`~sim_bridge.perturbation.WorldDraw.row`)
changes the ground's friction, the root link's mass (and a payload at its centre of mass)
and the servos' torque and speed for one episode, and puts them back after it
(:func:`perturbed_sim`); it adds noise to the laser's beams and loses some
(:func:`perturbed_ranges`, seeded by the episode's key), and damages a leg or a side
(:mod:`sim_bridge.legged.damaged`). The episode runner delays
primitives by whole cycles (:mod:`sim_bridge.legged.episode`). Nothing is changed for
identity values, so an unperturbed world runs the nominal simulation bit for bit.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Iterator

import numpy as np

from sim_bridge.legged.damaged import apply_damage
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.quiet_pybullet import p


@contextlib.contextmanager
def perturbed_sim(sim: LeggedSim, world: dict | None) -> Iterator[None]:
    """Run the block with ``sim``'s friction, mass and servos as ``world`` draws them.

    ``world``: one :meth:`~sim_bridge.perturbation.WorldDraw.row` (factors
    ``friction``, ``body_mass``, ``servo_strength``, ``servo_speed``; ``payload`` as a share
    of the body's mass, ``damage`` if any), or None. The body is the URDF's root link (the
    hexapod's box, the A1's trunk). Only values other than the identity are touched, and the
    nominal ones are put back afterwards (a saved state does not hold dynamics).
    """
    if not world:
        yield
        return
    c = sim.client
    friction = sim.physics.friction
    info = p.getDynamicsInfo(sim.robot, -1, physicsClientId=c)
    mass, inertia = info[0], info[2]  # kg and kg m^2 (principal axes) of the root link
    torques, settings = list(sim.torques), sim.settings
    mass_factor = world["body_mass"] + world["payload"]
    restore = None
    try:
        if world["friction"] != 1.0:
            # Contact friction is the product of both bodies' coefficients: scaling the
            # ground's scales every foot contact.
            p.changeDynamics(
                sim.ground, -1, lateralFriction=friction * world["friction"], physicsClientId=c
            )
        if mass_factor != 1.0:
            # The same shape, heavier: inertia scales with the mass.
            p.changeDynamics(
                sim.robot,
                -1,
                mass=mass * mass_factor,
                localInertiaDiagonal=[i * mass_factor for i in inertia],
                physicsClientId=c,
            )
        if world["servo_strength"] != 1.0:
            sim.torques = [t * world["servo_strength"] for t in torques]
        if world.get("damage"):  # after the strength: a weak leg is weaker still
            restore = apply_damage(sim, world["damage"], sim.torques)
        if world["servo_speed"] != 1.0:
            servo = dataclasses.replace(
                settings.servo, max_velocity=settings.servo.max_velocity * world["servo_speed"]
            )
            sim.settings = dataclasses.replace(settings, servo=servo)
        yield
    finally:
        if world["friction"] != 1.0:
            p.changeDynamics(sim.ground, -1, lateralFriction=friction, physicsClientId=c)
        if mass_factor != 1.0:
            p.changeDynamics(
                sim.robot, -1, mass=mass, localInertiaDiagonal=inertia, physicsClientId=c
            )
        sim.torques, sim.settings, sim.locked = torques, settings, {}
        if restore is not None:
            restore()


def perturbed_ranges(ranges: np.ndarray, world: dict | None, cycle: int) -> np.ndarray:
    """Laser ``ranges`` ``(beams,)`` (m) with the drawn noise and dropouts.

    The noise's sd is ``world["range_noise"]`` (m); each beam is lost with chance
    ``world["dropout"]`` and then reads +inf, beyond any range (no echo, REP 117).
    Seeded by the world's key and the cycle, so an episode's noise does not depend on the
    worker that runs it.
    """
    if not world or (world["range_noise"] <= 0.0 and world["dropout"] <= 0.0):
        return ranges
    rng = np.random.default_rng([world["key"], cycle])
    noisy = np.asarray(ranges, dtype=np.float64) + world["range_noise"] * rng.standard_normal(
        len(ranges)
    )
    lost = rng.random(len(ranges)) < world["dropout"]
    return np.where(lost, math.inf, noisy)
