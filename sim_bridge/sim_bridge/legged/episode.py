"""One legged robot's maze episode in PyBullet, with the onboard controller code.

Each control cycle (0.1 s): scan the laser and read the pose, turn them into inputs with
the laser and radar nodes' own code (:class:`~evorbc_ros.laser.LaserToRangefinders`,
:class:`~evorbc_ros.goal.GoalInputs`), activate the network
(:class:`~evorbc_ros.network.CompiledNetwork`), pick the primitive (EvoRBC: mapping and
nearest-primitive lookup; standard NEAT: the outputs are the genes), and run the
physics for one period with the joint targets of eq. 10 at every physics step (time since
the gait began). The episode ends at the target, when the body has fallen over, or at
the time limit.

A cycle whose network outputs are not finite runs no primitive, as onboard (the
arbitrator's empty message, :mod:`evorbc_ros.hexapod_executor`): every joint holds the
target being tracked, that is the last primitive's target at the cycle's first step, or
the joints' start positions before any primitive. The gait clock starts with the first
primitive, as the executor's does.

The ROS graph computes the same numbers from the same messages, so a lockstep run
reproduces an episode cycle by cycle. Every legged robot runs here, the hexapod
(``config/robots/hexapod.yaml``) as the A1; tests pin the hexapod's episodes to those of
the code it had before (``tests/test_legged_hexapod.py``).

A perturbed world (docs/design.md section 21, :mod:`sim_bridge.legged.perturbed`) changes
the ground's friction, the body's mass (and a payload at its centre), the servos' torque
and speed for one episode and puts them back after it; delays primitives by whole cycles;
and adds noise to the laser's beams and loses some (seeded by the episode's key). Nothing
is changed for identity values.
"""

from __future__ import annotations

import collections
import math
from dataclasses import dataclass

import numpy as np

from evorbc_ros.adaptation import AdaptationSettings, OnlineAdaptation, adapted_choice
from evorbc_ros.controller_kinds import ControllerKind, controller_kind, direct_genes
from evorbc_ros.goal import GoalInputs, yaw_from_quaternion
from evorbc_ros.laser import LaserToRangefinders
from evorbc_ros.mapping import NO_PRIMITIVE, MappingFunction, PrimitiveLookup, choose_primitive
from evorbc_ros.network import NetworkSpec
from evorbc_ros.robots.legged import LeggedGaitTable, gait_step_times
from evorbc_ros.sensors import SensorLayout
from sim_bridge.legged.maze_sims import MazeSims
from sim_bridge.legged.perturbed import perturbed_ranges, perturbed_sim
from sim_bridge.legged.physics import LeggedSim
from sim_bridge.legged.scanner import Scanner
from sim_bridge.legged.settings import LeggedRobotSettings
from sim_bridge.maze import Maze


@dataclass(frozen=True)
class LeggedController:
    """How network outputs become a primitive (picklable, sent to the workers)."""

    kind: ControllerKind  # may be given by name
    mapping: str | None = None
    genes: np.ndarray | None = None  # (n, 1 + 3 k) repertoire genes (EvoRBC)
    behaviour: np.ndarray | None = None  # (n, 2) m, repertoire behaviours (EvoRBC)
    key: str = ""  # identifies the controller, so workers build its lookup grid once

    def __post_init__(self) -> None:
        object.__setattr__(self, "kind", controller_kind(self.kind))


@dataclass(frozen=True)
class LeggedAdaptation:
    """An EvoRBC controller's onboard adaptation, as the arbitrator node builds it (picklable).

    ``recorded``: ``(n, 3)`` the repertoire's outcomes ``(dx m, dy m, dheading rad)`` over
    ``horizon`` s (:func:`evorbc_ros.adaptation.outcome_table`); ``expected``: ``(n, 3)``
    what an observation should read, or None (the recorded outcomes, as the node has).
    """

    recorded: np.ndarray
    horizon: float
    settings: AdaptationSettings
    expected: np.ndarray | None = None

    def start(self) -> OnlineAdaptation:
        """A fresh model: each episode starts from the prior."""
        return OnlineAdaptation(self.recorded, self.horizon, self.settings, self.expected)


@dataclass(frozen=True)
class LeggedWorld:
    """Everything an episode needs besides the controller (picklable)."""

    mazes: tuple[Maze, ...]
    layout: SensorLayout
    settings: LeggedRobotSettings
    n_cycles: int

    def scanner(self) -> Scanner:
        """The laser scanner whose beams are the layout's rays."""
        return Scanner.from_layout(self.layout.rangefinders)


class _Chooser:
    """Network outputs -> genes, as the arbitrator or a standard controller does."""

    def __init__(self, controller: LeggedController, settings: LeggedRobotSettings):
        self.kind = controller.kind
        if self.kind.uses_repertoire:
            self.genes = np.asarray(controller.genes, dtype=np.float64)
            self.table = LeggedGaitTable(self.genes, settings.gait, settings.name)
            self.mapping = MappingFunction.for_behaviours(controller.mapping, controller.behaviour)
            self.lookup = PrimitiveLookup.build(controller.behaviour, self.mapping.domain())
        self.settings = settings

    def choose(
        self, out: np.ndarray, adaptation: OnlineAdaptation | None = None
    ) -> tuple[int, LeggedGaitTable | None, np.ndarray]:
        """``(primitive index or -1, gait table, row)`` for one activation.

        No table (None) when the outputs are not finite: no primitive runs this cycle.
        ``adaptation``: an EvoRBC controller's, fed this cycle's pose; it matches the
        grid's choice as :meth:`evorbc_ros.arbitration.Controller.step` does.
        """
        if self.kind.uses_repertoire:
            index, x, y = choose_primitive(self.mapping, self.lookup, out[0], out[1])
            if adaptation is not None:
                index = adapted_choice(adaptation, self.lookup, index, x, y)
            if index == NO_PRIMITIVE:
                return index, None, np.array([0])
            return index, self.table, np.array([index])
        genes = direct_genes(out)
        if genes is None:
            return NO_PRIMITIVE, None, np.array([0])
        s = self.settings
        return -1, LeggedGaitTable(genes, s.gait, s.name), np.array([0])


class EpisodeRunner:
    """Runs episodes in per-maze simulations kept alive between calls."""

    def __init__(self, world: LeggedWorld):
        self.world = world
        self.scanner = world.scanner()
        self.laser = LaserToRangefinders(world.layout.rangefinders)
        self.goal = GoalInputs(world.layout)
        w = world
        self.sims = MazeSims(w.mazes, lambda boxes: LeggedSim(w.settings, boxes))
        self.choosers: dict[str, _Chooser] = {}
        physics = world.settings.physics
        self.per_period = physics.steps(world.settings.control_period)
        self.dt = physics.dt  # s per physics step, the gait clock's tick
        self.fallen_tilt = world.settings.fallen_tilt

    def chooser(self, controller: LeggedController) -> _Chooser:
        """The chooser of ``controller`` (built once per controller key)."""
        if controller.key not in self.choosers:
            self.choosers = {controller.key: _Chooser(controller, self.world.settings)}
        return self.choosers[controller.key]

    def sim(self, maze: int | Maze) -> LeggedSim:
        """The simulation of task maze ``maze`` or of a generated maze (built on first use)."""
        return self.sims.get(maze)[1]

    def inputs(
        self,
        sim: LeggedSim,
        maze: Maze,
        base: tuple | None = None,
        world: dict | None = None,
        cycle: int = 0,
    ) -> np.ndarray:
        """The arbitrator's inputs now: laser groups, then goal bearing (and motion).

        ``base``: the body's :meth:`~LeggedSim.base_pose` read since the last step, or
        None to read it now. ``world``, ``cycle``: a perturbed world's row and the cycle
        (laser noise and dropouts, :func:`~sim_bridge.legged.perturbed.perturbed_ranges`);
        the cycle also stamps the pose for a motion input, as the bridge stamps its
        odometry (``round(cycle x period)`` ns).
        """
        base = sim.base_pose() if base is None else base
        s = self.scanner
        ranges = perturbed_ranges(s.scan(sim, base), world, cycle)
        rf = self.laser.readings(s.angle_min, s.angle_increment, ranges, s.range_min, s.range_max)
        (x, y, _), orn = base
        yaw = yaw_from_quaternion(*orn)
        stamp = round(cycle * self.world.settings.control_period * 1e9)
        goal = self.goal.readings(x, y, yaw, maze.target[0], maze.target[1], stamp_ns=stamp)
        return np.concatenate([rf, goal])

    def run(
        self,
        network: NetworkSpec,
        controller: LeggedController,
        maze_index: int | Maze,
        start: tuple[float, float, float],
        record: bool = False,
        world: dict | None = None,
        adaptation: LeggedAdaptation | None = None,
    ) -> dict:
        """One episode from ``start`` ``(x, y, heading)`` in maze ``maze_index`` (or a Maze).

        ``world``: a perturbed world's row
        (:meth:`~sim_bridge.perturbation.WorldDraw.row`), or None. ``adaptation``: an
        EvoRBC controller adapting from the prior, fed each cycle as the arbitrator node
        is in a lockstep graph: the odometry pose of the body at the cycle's start (the
        bridge's ``odom``: position and the yaw of PyBullet's orientation, stamped
        ``round(cycle x period)`` ns), then the choice (docs/design/adaptation.md).

        Returns:
            ``{"reached", "fell", "cycles", "final_distance", "initial_distance", "start_xy",
            "end_xy"}`` (distances and positions in m, the body's first and last x, y) and,
            with ``record``, ``"pose" (cycles + 1, 3)``, ``"choice" (cycles,)`` and
            ``"outputs" (cycles, n_outputs)``; with ``adaptation``, ``"observations"``
            and ``"observed"`` (primitives in the model) at the end.

        """
        maze, sim = self.sims.get(maze_index)  # a task maze's index or a generated maze
        sim.reset(*start)
        # A fresh compile per episode: a recurrent network's state starts at 0 here; so
        # does a motion input's window.
        net = network.compile()
        self.goal.reset()
        chooser = self.chooser(controller)
        tx, ty = maze.target
        # The body's pose is read once per cycle (a PyBullet state request each time) and
        # serves the pose, the laser and the goal inputs until the next physics step.
        base = sim.base_pose()
        x, y, heading, _ = sim.pose(base)
        initial = math.hypot(x - tx, y - ty)
        start_xy = (x, y)
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
        online = adaptation.start() if adaptation is not None else None
        period = self.world.settings.control_period
        with perturbed_sim(sim, world):
            for cycle in range(self.world.n_cycles):
                out = net.activate(self.inputs(sim, maze, base, world, cycle))
                if online is None:
                    choice = chooser.choose(out)
                else:
                    (px, py, _), orn = base
                    yaw = yaw_from_quaternion(*orn)
                    online.put_pose(round(cycle * period * 1e9), px, py, yaw)
                    choice = chooser.choose(out, online)
                # Latency: the choice made ``latency`` cycles ago acts now (none before).
                queue.append(choice)
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
                tilt, _ = sim.run(targets, max_tilt=self.fallen_tilt)
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
                if tilt > self.fallen_tilt:
                    fell = True  # cycles stays n_cycles: eq. 5 scores where it lies
                    break
        result = {
            "reached": reached,
            "fell": fell,
            "cycles": cycles,
            "final_distance": distance,
            "initial_distance": initial,
            "start_xy": start_xy,
            "end_xy": (x, y),
        }
        if online is not None:
            result["observations"] = online.model.observations
            result["observed"] = online.model.used
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
