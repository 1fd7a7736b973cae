"""One hexapod maze episode in PyBullet, with the onboard controller code (worker side).

Each control cycle (0.1 s): scan the laser and read the pose, turn them into inputs with
the laser and radar nodes' own code (:class:`~evorbc_ros.laser.LaserToRangefinders`,
:class:`~evorbc_ros.goal.GoalInputs`), activate the network
(:class:`~evorbc_ros.network.CompiledNetwork`), pick the primitive (EvoRBC: mapping and
nearest-primitive lookup; standard NEAT: the outputs are the 37 genes), and run the
physics for one period with the joint targets of eq. 10 at every physics step (time since
the gait began). The episode ends at the target, when the body has fallen over, or at
the time limit.

A cycle whose network outputs are not finite runs no primitive, as onboard (the
arbitrator's empty message, :mod:`evorbc_ros.hexapod_executor`): every joint holds the
target being tracked, that is the last primitive's target at the cycle's first step, or
the joints' start positions before any primitive. The gait clock starts with the first
primitive, as the executor's does.

The ROS graph computes the same numbers from the same messages, so a lockstep run
reproduces an episode cycle by cycle.

A perturbed world (docs/design.md section 21) changes the ground's friction, the body's
mass (and a payload at its centre), the servos' torque and speed for one episode and puts
them back after it; delays primitives by whole cycles; and adds noise to the laser's beams
and loses some (seeded by the episode's key). Nothing is changed for identity values.
"""

from __future__ import annotations

import collections
import contextlib
import dataclasses
import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from evorbc_ros.goal import GoalInputs, yaw_from_quaternion
from evorbc_ros.laser import LaserToRangefinders
from evorbc_ros.mapping import NO_PRIMITIVE, MappingFunction, PrimitiveLookup, choose_primitive
from evorbc_ros.network import NetworkSpec
from evorbc_ros.robots.hexapod import GaitTable, HexapodGeometry, gait_step_times
from evorbc_ros.sensors import SensorLayout
from sim_bridge.hexapod.maze_world import FALLEN_TILT
from sim_bridge.hexapod.physics import HexapodSim, PhysicsSettings
from sim_bridge.hexapod.scanner import Scanner
from sim_bridge.maze import Maze
from sim_bridge.maze_sims import MazeSims
from sim_bridge.quiet_pybullet import p


@contextlib.contextmanager
def perturbed_sim(sim: HexapodSim, world: dict | None) -> Iterator[None]:
    """Run the block with ``sim``'s friction, mass and servos as ``world`` draws them.

    ``world``: one :meth:`~offline_evolution.maze_task.perturbation.WorldDraw.row` (factors
    ``friction``, ``body_mass``, ``servo_strength``, ``servo_speed``; ``payload`` as a share
    of the body's mass), or None. Only values other than the identity are touched, and the
    nominal ones are put back afterwards (a saved state does not hold dynamics).
    """
    if not world:
        yield
        return
    c = sim.client
    friction = sim.physics.friction
    info = p.getDynamicsInfo(sim.robot, -1, physicsClientId=c)
    mass, inertia = info[0], info[2]  # kg and kg m^2 (principal axes) of the body
    torques, settings = list(sim.torques), sim.settings
    mass_factor = world["body_mass"] + world["payload"]
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
        sim.torques, sim.settings = torques, settings


def perturbed_ranges(
    ranges: np.ndarray, world: dict | None, cycle: int, range_max: float
) -> np.ndarray:
    """Laser ``ranges`` (m) with the drawn noise (sd ``range_noise`` m) and dropouts.

    A lost beam reads beyond ``range_max`` (no echo). Seeded by the world's key and the
    cycle, so an episode's noise does not depend on the worker that runs it.
    """
    if not world or (world["range_noise"] <= 0.0 and world["dropout"] <= 0.0):
        return ranges
    rng = np.random.default_rng([world["key"], cycle])
    noisy = np.asarray(ranges, dtype=np.float64) + world["range_noise"] * rng.standard_normal(
        len(ranges)
    )
    lost = rng.random(len(ranges)) < world["dropout"]
    return np.where(lost, math.inf, noisy)


@dataclass(frozen=True)
class HexapodController:
    """How network outputs become a primitive (picklable, sent to the workers)."""

    kind: str  # "evorbc" or "standard"
    mapping: str | None = None
    genes: np.ndarray | None = None  # (n, 37) repertoire genes (EvoRBC)
    behaviour: np.ndarray | None = None  # (n, 2) m, repertoire behaviours (EvoRBC)
    key: str = ""  # identifies the controller, so workers build its lookup grid once


@dataclass(frozen=True)
class HexapodWorld:
    """Everything an episode needs besides the controller (picklable)."""

    mazes: tuple[Maze, ...]
    layout: SensorLayout
    geometry: HexapodGeometry
    physics: PhysicsSettings
    n_cycles: int

    def scanner(self) -> Scanner:
        """The laser scanner whose beams are the layout's rays."""
        return Scanner.from_layout(self.layout.rangefinders)


class _Chooser:
    """Network outputs -> genes, as the arbitrator or a standard controller does."""

    def __init__(self, controller: HexapodController, geometry: HexapodGeometry):
        self.kind = controller.kind
        if self.kind == "evorbc":
            self.genes = np.asarray(controller.genes, dtype=np.float64)
            self.table = GaitTable(self.genes, geometry)
            self.mapping = MappingFunction.for_behaviours(controller.mapping, controller.behaviour)
            self.lookup = PrimitiveLookup.build(controller.behaviour, self.mapping.domain())
        self.geometry = geometry

    def choose(self, out: np.ndarray) -> tuple[int, GaitTable | None, np.ndarray]:
        """``(primitive index or -1, gait table, row)`` for one activation.

        No table (None) when the outputs are not finite: no primitive runs this cycle.
        """
        if self.kind == "evorbc":
            index = choose_primitive(self.mapping, self.lookup, out[0], out[1])[0]
            if index == NO_PRIMITIVE:
                return index, None, np.array([0])
            return index, self.table, np.array([index])
        if not np.all(np.isfinite(out)):
            return NO_PRIMITIVE, None, np.array([0])
        genes = 2.0 * np.clip(out, 0.0, 1.0) - 1.0
        return -1, GaitTable(genes, self.geometry), np.array([0])


class EpisodeRunner:
    """Runs episodes in per-maze simulations kept alive between calls."""

    def __init__(self, world: HexapodWorld):
        self.world = world
        self.scanner = world.scanner()
        self.laser = LaserToRangefinders(world.layout.rangefinders)
        self.goal = GoalInputs(world.layout)
        w = world
        self.sims = MazeSims(w.mazes, lambda boxes: HexapodSim(w.geometry, w.physics, boxes))
        self.choosers: dict[str, _Chooser] = {}
        self.per_period = world.physics.steps(world.geometry.control_period)
        self.dt = world.physics.dt  # s per physics step, the gait clock's tick

    def chooser(self, controller: HexapodController) -> _Chooser:
        """The chooser of ``controller`` (built once per controller key)."""
        if controller.key not in self.choosers:
            self.choosers = {controller.key: _Chooser(controller, self.world.geometry)}
        return self.choosers[controller.key]

    def sim(self, maze: int | Maze) -> HexapodSim:
        """The simulation of task maze ``maze`` or of a generated maze (built on first use)."""
        return self.sims.get(maze)[1]

    def inputs(
        self,
        sim: HexapodSim,
        maze: Maze,
        base: tuple | None = None,
        world: dict | None = None,
        cycle: int = 0,
    ) -> np.ndarray:
        """The arbitrator's inputs now: laser groups, then goal bearing.

        ``base``: the body's :meth:`~HexapodSim.base_pose` read since the last step, or
        None to read it now. ``world``, ``cycle``: a perturbed world's row and the cycle
        (laser noise and dropouts, :func:`perturbed_ranges`).
        """
        base = sim.base_pose() if base is None else base
        s = self.scanner
        ranges = perturbed_ranges(s.scan(sim, base), world, cycle, s.range_max)
        rf = self.laser.readings(s.angle_min, s.angle_increment, ranges, s.range_min, s.range_max)
        (x, y, _), orn = base
        yaw = yaw_from_quaternion(*orn)
        goal = self.goal.readings(x, y, yaw, maze.target[0], maze.target[1])
        return np.concatenate([rf, goal])

    def run(
        self,
        network: NetworkSpec,
        controller: HexapodController,
        maze_index: int | Maze,
        start: tuple[float, float, float],
        record: bool = False,
        world: dict | None = None,
    ) -> dict:
        """One episode from ``start`` ``(x, y, heading)`` in maze ``maze_index`` (or a Maze).

        ``world``: a perturbed world's row (:func:`perturbed_sim`), or None.

        Returns:
            ``{"reached", "fell", "cycles", "final_distance", "initial_distance"}`` and,
            with ``record``, ``"pose" (cycles + 1, 3)``, ``"choice" (cycles,)`` and
            ``"outputs" (cycles, n_outputs)``.

        """
        maze, sim = self.sims.get(maze_index)  # a task maze's index or a generated maze
        sim.reset(*start)
        net = network.compile()
        chooser = self.chooser(controller)
        tx, ty = maze.target
        # The body's pose is read once per cycle (a PyBullet state request each time) and
        # serves the pose, the laser and the goal inputs until the next physics step.
        base = sim.base_pose()
        x, y, heading, _ = sim.pose(base)
        initial = math.hypot(x - tx, y - ty)
        distance = initial
        reached = fell = False
        poses, choices, outputs = [(x, y, heading)], [], []
        cycles = self.world.n_cycles
        # The executor's state: the physics step its gait clock started at (the first
        # primitive), the last gait run and the target held while none runs (rad).
        gait_start, last, last_row = None, None, None
        held = sim.joint_states()[0]  # before any primitive: where the joints stand
        latency = int(world["latency_cycles"]) if world else 0
        queue = collections.deque([(NO_PRIMITIVE, None, np.array([0]))] * latency)
        with perturbed_sim(sim, world):
            for cycle in range(self.world.n_cycles):
                out = net.activate(self.inputs(sim, maze, base, world, cycle))
                # Latency: the choice made ``latency`` cycles ago acts now (none before).
                queue.append(chooser.choose(out))
                index, table, row = queue.popleft()
                if table is not None:
                    if gait_start is None:
                        gait_start = sim.steps_done
                    last, last_row = table, row
                    times = gait_step_times(sim.steps_done - gait_start, self.per_period, self.dt)
                    targets = table.joint_targets(times, np.repeat(row, len(times)))
                    held = None
                else:
                    if held is None:  # the last gait's target at this cycle's first step
                        now = gait_step_times(sim.steps_done - gait_start, 1, self.dt)
                        held = last.joint_targets(now, last_row)[0]
                    targets = np.repeat(held[None, :], self.per_period, axis=0)
                tilt, _ = sim.run(targets, max_tilt=FALLEN_TILT)
                base = sim.base_pose()
                x, y, heading, _ = sim.pose(base)
                distance = math.hypot(x - tx, y - ty)
                if record:
                    poses.append((x, y, heading))
                    choices.append(index)
                    outputs.append(out)
                if distance <= maze.target_radius:
                    reached, cycles = True, cycle + 1
                    break
                if tilt > FALLEN_TILT:
                    fell = True  # cycles stays n_cycles: eq. 5 scores where it lies
                    break
        result = {
            "reached": reached,
            "fell": fell,
            "cycles": cycles,
            "final_distance": distance,
            "initial_distance": initial,
        }
        if record:
            result["pose"] = np.array(poses)
            result["choice"] = np.array(choices, dtype=np.int64)
            result["outputs"] = np.array(outputs).reshape(len(choices), -1)
        return result

    def close(self) -> None:
        """Disconnect every simulation."""
        for sim in self.sims.values():
            sim.close()
        self.sims.clear()
