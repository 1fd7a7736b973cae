"""``sim_bridge``: the PyBullet-backed simulated robot and maze as a ROS 2 node.

Publishes ``/clock`` (rosgraph_msgs/Clock, simulated time), ``scan``
(sensor_msgs/LaserScan, frame ``base_link``), ``odom`` (nav_msgs/Odometry, ``odom`` ->
``base_link``), ``goal`` (geometry_msgs/PointStamped in ``odom``, latched) and
``joint_states`` (sensor_msgs/JointState). Applies ros2_control commands
(:mod:`sim_bridge.bridge_robots`):

* 4WS robots: ``steering_position_controller/commands`` (rad) and
  ``wheel_velocity_controller/commands`` (rad/s; the robot's single wheel speed is their
  mean times the wheel radius); four steering and four wheel joints.
* the hexapod: ``joint_trajectory_controller/joint_trajectory`` (trajectory_msgs/
  JointTrajectory, 18 joints, rad), one control period of targets that the physics steps
  follow; a 25-beam scan over [-90, 90] deg.

Modes:
* ``lockstep``: wait until the graph is connected; then publish the state, wait for one new
  message on both command topics, step 0.1 s, repeat: deterministic and as fast as the
  graph answers. A slow node is waited for. If a node leaves the graph and comes back (a
  restart), the state is published again and the run goes on where it was; so it is after
  ``lockstep_timeout`` s without commands.
* ``realtime``: step every 0.1 s of wall time with the latest commands.

One graph per ROS domain and namespace: a second publisher on a topic of the graph (this
bridge's outputs, the sensor readings, the primitive, the commands) is another graph's
node, whose answers this bridge would take for its own. In lockstep the run then stops
with one line naming the topic (status 1, no result written) rather than finish an episode
that silently left the offline one; in realtime it is a warning (docs/design.md section 9,
"One graph per domain").

The episode ends at the target, when the hexapod falls over, or after ``episode_time``;
the result (reached, fell, time, eq. 5 fitness, trajectory) is logged and, if
``result_file`` is set, written as JSON.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time

import numpy as np
import rclpy
from builtin_interfaces.msg import Time
from geometry_msgs.msg import PointStamped
from nav_msgs.msg import Odometry
from rclpy.duration import Duration
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState, LaserScan
from std_msgs.msg import Empty

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.config import ConfigError
from evorbc_ros.health import WARN, Health, Meter
from evorbc_ros.nodes.common import (
    LATCHED,
    RELIABLE,
    Executor,
    StartupError,
    init_ros,
    logged_startup,
    quiet_teardown,
    robot_named,
    running,
    stop_requested,
)
from evorbc_ros.nodes.diagnostics import DiagnosticsPublisher
from evorbc_ros.nodes.parameters import ParameterGuard, declare_all
from evorbc_ros.robots import registry
from sim_bridge.bridge_parameters import PARAMETERS, REMOVED
from sim_bridge.rejoins import RejoinWatch
from sim_bridge.verdict import episode_verdict

#: Longest time (wall s) the lockstep bridge waits, after its final state, for every reader
#: to acknowledge its state messages. A recorder on a loaded machine may be many cycles
#: behind when the run ends; a bridge that exits first takes those messages with it
#: (docs/design/ros-graph.md, "Recording and playback"). 10 s was too short at load 8: a
#: recorder 320 cycles behind had taken every /clock, /scan and /odom but 507 of 819
#: /joint_states. A reader that never acknowledges is a dead node, which DDS drops at the
#: end of its lease (20 s), ending the wait: a longer limit costs nothing there.
DELIVERY_LIMIT = 30.0
#: Wall s of one wait for acknowledgements between checks for a stop request.
ACK_SLICE = 0.1

#: Topics of the graph besides the commands: each has exactly one publisher in one run.
GRAPH_TOPICS = (
    "/clock",
    "scan",
    "odom",
    "joint_states",
    "evorbc/rangefinders",
    "evorbc/goal_sectors",
)


class SharedGraphError(Exception):
    """Another graph publishes on this run's topics (the message names one)."""


def stamp(seconds: float) -> Time:
    """A builtin_interfaces/Time for ``seconds``."""
    ns = round(seconds * 1e9)
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


class SimBridgeNode(Node):
    """The simulated robot (any registered robot: 4WS, hexapod, a plugin's) in a maze."""

    def __init__(self, **kwargs) -> None:
        super().__init__("sim_bridge", **kwargs)
        with logged_startup(self):
            p = self.params = declare_all(self, PARAMETERS, "at start-up", REMOVED)
            robot = p["robot"]
            spec = robot_named(robot)
            self.mode = p["mode"]
            episode_time = p["episode_time"] or spec.episode_time
            self.lockstep_timeout = p["lockstep_timeout"]
            self.wait_subscribers = list(p["wait_for_subscribers"])
            self.wait_publishers = list(p["wait_for_publishers"]) or [
                *spec.command_topics,
                "evorbc/primitive",
            ]
            self.startup_timeout = p["startup_timeout"]
            self.result_file = p["result_file"]
            self.progress_period = p["progress_period"]
            # Imported here, after rclpy.init: numba and PyBullet take seconds to load, and
            # a graph shut down meanwhile (another node refused to start) would otherwise
            # interrupt the import with a KeyboardInterrupt traceback.
            from sim_bridge.bridge_robots import bridge_robot_class

            maze, self.maze_scale, warning = robot_maze(
                p["maze"], p["maze_scale"], spec.footprint_radius, robot
            )
            if warning:  # offline runs say the same in the same words
                self.get_logger().warning(warning)
            kind = bridge_robot_class(robot)
            pose = self._start_pose(maze, p["start"], p["seed"], spec.footprint_radius, robot)
            self.robot = kind(self, robot, maze, pose, episode_time, p["gui"])
            self._perturb(p["perturb"], p["seed"])
        ParameterGuard(self, PARAMETERS, "at start-up")
        self.steps = Meter()
        self.diagnostics = DiagnosticsPublisher(self, p["diagnostics_period"], self.health, robot)
        self.world = self.robot.world
        self.trajectory = [list(self.world.pose)]
        self.fresh = dict.fromkeys(self.robot.command_keys, False)
        self.command_times: list[float] = []  # wall-clock arrivals of the last key (s)
        self.loop_start = None  # wall clock when the episode started (after the graph)

        self.clock_pub = self.create_publisher(Clock, "/clock", RELIABLE)
        self.scan_pub = self.create_publisher(LaserScan, "scan", RELIABLE)
        self.odom_pub = self.create_publisher(Odometry, "odom", RELIABLE)
        self.joint_pub = self.create_publisher(JointState, "joint_states", RELIABLE)
        self.goal_pub = self.create_publisher(PointStamped, "goal", LATCHED)
        self.subs = self.robot.subscribe(self.on_command)
        self.next_progress = self.progress_period
        goal = PointStamped()  # latched: published once, late joiners still get it
        goal.header.frame_id = "odom"
        goal.point.x, goal.point.y = self.world.maze.target
        self.goal_pub.publish(goal)
        self.get_logger().info(
            f"{robot} in maze {maze.name}{scaled(self.maze_scale)} ({self.mode}), start "
            f"({pose[0]:.3f}, {pose[1]:.3f}, {math.degrees(pose[2]):.1f} deg)"
        )

    @staticmethod
    def _start_pose(
        maze, start: str, seed: int, clearance: float, robot: str = "the robot"
    ) -> tuple[float, float, float]:
        """The start pose; its footprint (``clearance`` m about the centre) must be clear.

        Raises:
            StartupError: the robot does not fit the maze where it starts (nominal or
                random start), or an explicit ``start`` is malformed or touches a wall.
        """
        misfit = maze.start_misfit(clearance, robot)
        if start in ("nominal", "random") and misfit:
            # Not the user's start: the maze's own start region is too narrow for it.
            own = registry.lookup(robot).maze if registry.known(robot) else maze.name
            hint = "" if maze.name == own else f"; its maze is {own}"
            raise StartupError(misfit + hint)
        if start == "random":
            try:
                return tuple(maze.sample_starts(np.random.default_rng(seed), 1, clearance)[0])
            except ValueError as e:  # a negative seed, or no start in the region fits
                raise StartupError(f"parameter start random (seed {seed}): {e}") from None
        if start == "nominal":
            return maze.start_pose
        try:
            x, y, h = (float(v) for v in start.split(","))
        except ValueError:
            raise StartupError(
                f"parameter start must be nominal, random or 'x,y,heading_deg', got {start!r}"
            ) from None
        if not all(math.isfinite(v) for v in (x, y, h)):
            raise StartupError(f"parameter start must be finite, got {start!r}")
        room = maze.clearance(x, y)
        if room < clearance:
            raise StartupError(
                f"parameter start: ({x:.2f}, {y:.2f}) m is {room:.3f} m from a wall of maze "
                f"{maze.name}, but the robot needs {clearance:.3f} m"
            )
        return x, y, math.radians(h)

    # -- commands ----------------------------------------------------------------------

    def _perturb(self, name: str, seed: int) -> None:
        """Apply one world of perturbation set ``name``, drawn from ``default_rng([seed, 1])``.

        Logs the world and what of the set this robot's bridge cannot apply.
        """
        if name == "none":
            return
        from sim_bridge.perturbation import load_perturbations

        try:
            perturbation = load_perturbations(name)
        except ConfigError as e:
            raise StartupError(f"parameter perturb: {e}") from None
        draw = perturbation.draw(np.random.default_rng([seed, 1]), 1)
        try:
            applied = self.robot.perturb(draw)
        except ConfigError as e:  # a fixed leg this robot has not
            raise StartupError(f"parameter perturb {name}: {e}") from None
        if perturbation.damage is not None and perturbation.damage.kind not in applied:
            raise StartupError(
                f"parameter perturb {name}: this robot's simulation cannot apply damage "
                f"{perturbation.damage.kind}"
            )
        wanted = perturbation.perturbed()
        row = draw.row(0)
        shown = {q: round(v, 4) for q, v in row.items() if q in wanted}
        damage = ""
        if "damage" in row:
            from sim_bridge.damage import describe, part_names

            settings = getattr(self.robot.world, "settings", None)
            legs = tuple(getattr(settings, "foot_links", ()))
            damage = "; " + describe(row["damage"], part_names(row["damage"]["kind"], legs))[1]
        self.get_logger().info(
            f"perturbation set {perturbation.name} (seed {seed}): {shown}{damage}"
        )
        skipped = [q for q in wanted if q not in applied]
        if skipped:
            self.get_logger().warning(
                f"parameter perturb {name}: the bridge does not apply {', '.join(skipped)}"
            )

    def on_command(self, key: str) -> None:
        """A valid command for ``key`` has been stored by the robot adapter."""
        self.fresh[key] = True
        if key == self.robot.command_keys[-1]:
            self.command_times.append(time.monotonic())

    # -- publishing --------------------------------------------------------------------

    def publish_state(self) -> None:
        """Clock, scan, odometry and joint states at the current simulated time."""
        t = stamp(self.world.time)
        self.clock_pub.publish(Clock(clock=t))
        g = self.robot.scan_geometry
        scan = LaserScan()
        scan.header.stamp = t
        scan.header.frame_id = "base_link"
        scan.angle_min = g.angle_min
        scan.angle_max = g.angle_max
        scan.angle_increment = g.angle_increment
        scan.range_min = g.range_min
        scan.range_max = g.range_max
        scan.ranges = [float(r) for r in self.robot.scan()]
        self.scan_pub.publish(scan)
        (x, y, z), (qx, qy, qz, qw) = self.robot.body_pose()
        odom = Odometry()
        odom.header.stamp = t
        odom.header.frame_id = "odom"
        odom.child_frame_id = "base_link"
        odom.pose.pose.position.x = x
        odom.pose.pose.position.y = y
        odom.pose.pose.position.z = z
        o = odom.pose.pose.orientation
        o.x, o.y, o.z, o.w = qx, qy, qz, qw
        odom.twist.twist.linear.x, odom.twist.twist.angular.z = self.robot.twist()
        self.odom_pub.publish(odom)
        joints = JointState()
        joints.header.stamp = t
        self.robot.joint_state(joints)
        self.joint_pub.publish(joints)

    def advance(self) -> None:
        """Step the world with the latest commands and log progress."""
        self.robot.advance()
        self.steps.tick(time.monotonic())
        self.trajectory.append(list(self.world.pose))
        status = self.world.status()
        if status.time >= self.next_progress - 1e-9:
            self.next_progress += self.progress_period
            self.get_logger().info(
                f"t = {status.time:5.1f} s, {status.distance:.2f} m to the target"
            )

    def health(self, now: float) -> Health:
        """Simulated time, distance to the target, steps per wall second, missing nodes."""
        h = Health()
        status = self.world.status()
        h.add("mode", self.mode)
        h.add("simulated time (s)", status.time)
        h.add("distance to the target (m)", status.distance)
        h.add("steps per second", self.steps.rate(time.monotonic()))
        missing = self.missing()
        if missing:
            h.worse(WARN, f"waiting for {', '.join(missing)}")
        return h

    # -- running -----------------------------------------------------------------------

    def missing(self) -> list[str]:
        """The graph topics that lack a subscriber or publisher (a node is down).

        A topic named ``k`` times needs ``k`` of them: an adapting arbitrator subscribes
        ``odom`` beside the radar node, and a first state it missed would be sent again.
        """
        subs, pubs = self.wait_subscribers, self.wait_publishers
        out = [t for t in dict.fromkeys(subs) if self.count_subscribers(t) < subs.count(t)]
        return out + [t for t in dict.fromkeys(pubs) if self.count_publishers(t) < pubs.count(t)]

    def endpoints(self) -> frozenset:
        """The graph's endpoints the bridge waits on: ``(topic, endpoint GID)`` pairs.

        A restarted node comes back with new GIDs; a node that only dropped out of DDS
        discovery for a while (its lease missed under load) comes back with the same ones.
        """
        subs = (
            (t, bytes(i.endpoint_gid))
            for t in self.wait_subscribers
            for i in self.get_subscriptions_info_by_topic(self.resolve_topic_name(t))
        )
        pubs = (
            (t, bytes(i.endpoint_gid))
            for t in self.wait_publishers
            for i in self.get_publishers_info_by_topic(self.resolve_topic_name(t))
        )
        return frozenset((*subs, *pubs))

    def other_graph(self) -> str:
        """Which topic has a second publisher (another graph in this domain); "" if none.

        Two graphs in one ROS domain and namespace answer each other's states: each run
        then diverges from its offline episode, and its arbitrator records extra choices
        (docs/design.md section 9). A node killed without a clean exit also leaves its
        publisher behind until its DDS lease ends (about 20 s), so a node restarted within
        that time counts as a second one.
        """
        for topic in (*GRAPH_TOPICS, *self.wait_publishers):
            count = self.count_publishers(topic)
            if count > 1:
                domain = os.environ.get("ROS_DOMAIN_ID", "0")
                return (
                    f"{self.resolve_topic_name(topic)} has {count} publishers: another graph "
                    f"runs in ROS domain {domain} with the same namespace; give each graph "
                    "its own ROS_DOMAIN_ID or namespace"
                )
        return ""

    def check_alone(self) -> None:
        """Lockstep: stop before stepping with commands that may be another graph's.

        Raises:
            SharedGraphError: naming the topic.
        """
        problem = self.other_graph()
        if problem:
            raise SharedGraphError(problem)

    def spin_for(self, executor, seconds: float) -> None:
        """Process messages for ``seconds`` of wall time."""
        until = time.monotonic() + seconds
        while time.monotonic() < until and running():
            executor.spin_once(timeout_sec=0.05)

    def wait_for_graph(self, executor) -> None:
        """Wait until the controller's nodes are connected, so no first message is lost.

        In lockstep a lost first state would have to be sent again, and nodes that had
        already seen it would then answer twice: a lockstep run therefore starts only
        with its whole graph, warning every ``startup_timeout`` s while it waits (a
        loaded machine can take that long to start five processes; a node that fails
        ends the graph: docs/design/ros-graph.md, "Start-up"). In realtime the run
        starts without the missing nodes after ``startup_timeout`` s.
        """
        began = time.monotonic()
        deadline = began + self.startup_timeout
        heard: set[str] = set()
        ready = [
            self.create_subscription(Empty, t, lambda _, t=t: heard.add(t), LATCHED)
            for t in self.params["wait_for_ready"]
        ]

        def missing() -> list[str]:
            return self.missing() + [t for t in self.params["wait_for_ready"] if t not in heard]

        while missing() and running():
            executor.spin_once(timeout_sec=0.05)
            now = time.monotonic()
            if now >= deadline:
                if self.mode != "lockstep":
                    break
                gone = missing()
                if gone:
                    self.get_logger().warning(
                        f"still waiting for {', '.join(gone)} after {now - began:.0f} s: "
                        "a lockstep run starts with its whole graph"
                    )
                deadline = now + self.startup_timeout
        for sub in ready:
            self.destroy_subscription(sub)
        if not running():
            return  # stopped while waiting (the launch shut the graph down)
        if missing():
            self.get_logger().warning(f"starting without {', '.join(missing())}")
            return
        # Both ends of a new DDS connection match at about the same time; give the far
        # end a moment before the first reliable message.
        self.spin_for(executor, 0.3)

    def wait_for_commands(self, executor) -> None:
        """Wait for this cycle's commands, sending the state again only if it was lost.

        A slow node is simply waited for: sending the state twice would make the nodes
        that already answered answer twice, and the extra commands would be taken for the
        next cycle's. The state is sent again when a node has left the graph and come
        back as a new one (a restart: new endpoints), or, as a last resort, after
        ``lockstep_timeout`` s. A node that drops out of discovery and comes back with
        its old endpoints (a DDS lease missed on a loaded machine) lost no message: the
        connections are reliable, so nothing is sent again (docs/design.md section 9).
        """
        sent = time.monotonic()
        while not all(self.fresh.values()) and running():
            executor.spin_once(timeout_sec=0.01)
            now = time.monotonic()
            rejoined = False
            # Every 0.1 s of waiting, counted across cycles: fast cycles then still learn
            # endpoints discovered late (sim_bridge/rejoins.py).
            if now - self.looked > 0.1:
                self.looked = now
                gone = self.missing()
                seen = self.rejoins.check(gone, self.endpoints)
                if seen == "left":
                    self.get_logger().warning(f"lost {', '.join(gone)}; waiting for it")
                elif seen == "back":
                    self.get_logger().info("it is back with the same endpoints; waiting")
                rejoined = seen == "new"
            if rejoined or now - sent > self.lockstep_timeout:
                if rejoined:
                    self.spin_for(executor, 0.3)  # let the new node's connections settle
                self.get_logger().info(f"sending the state again for t = {self.world.time:.1f} s")
                self.publish_state()
                sent = time.monotonic()

    def run_lockstep(self) -> None:
        """The lockstep loop: state out, both commands in, step."""
        executor = Executor(context=self.context)
        executor.add_node(self)
        try:
            self.wait_for_graph(executor)
            self.check_alone()
            self.rejoins = RejoinWatch(self.endpoints())
            self.looked = time.monotonic()  # the last look at the graph's endpoints
            self.loop_start = time.monotonic()
            while not self.world.status().done and running():
                self.fresh = dict.fromkeys(self.fresh, False)
                self.publish_state()
                self.wait_for_commands(executor)
                self.check_alone()  # before the commands move the robot
                self.advance()
            if running():
                self.publish_state()  # final state for listeners
                self.deliver_state()
        finally:
            executor.remove_node(self)

    def deliver_state(self) -> None:
        """Wait until every reader has acknowledged the state messages, or DELIVERY_LIMIT.

        A reliable reader acknowledges a message once it holds it, so a recorder stopped
        after this bridge ends has the whole run to write. A reader that never acknowledges
        (a node that died without leaving the graph) costs the limit and a warning.
        """
        deadline = time.monotonic() + DELIVERY_LIMIT
        late = []
        for pub in (self.clock_pub, self.scan_pub, self.odom_pub, self.joint_pub):
            # In slices, so that a stop request (Ctrl-C) is not held up by a silent reader.
            while not pub.wait_for_all_acked(Duration(seconds=ACK_SLICE)):
                if not running() or time.monotonic() > deadline:
                    late.append(pub.topic_name)
                    break
        if not running():
            return
        if late:
            self.get_logger().warning(
                f"a reader did not acknowledge the last state on {', '.join(late)} within "
                f"{DELIVERY_LIMIT:.0f} s; it may lack the end of the run"
            )

    def run_realtime(self) -> None:
        """Step every 0.1 s of wall time with whatever commands are current."""
        executor = Executor(context=self.context)
        executor.add_node(self)
        period = self.world.dt
        try:
            self.wait_for_graph(executor)
            shared = self.other_graph()
            if shared:  # real time is not reproducible anyway: say so and go on
                self.get_logger().warning(shared)
            self.loop_start = time.monotonic()
            self.publish_state()
            next_tick = time.monotonic() + period
            while not self.world.status().done and running():
                executor.spin_once(timeout_sec=max(0.0, next_tick - time.monotonic()))
                if time.monotonic() >= next_tick:
                    next_tick += period
                    self.advance()
                    self.publish_state()
        finally:
            executor.remove_node(self)

    def finish(self, interrupted: bool = False) -> dict:
        """Write the result file and log the result through the node.

        A signal only asks the loops to end (docs/design.md section 9), so the context is
        still up here and the verdict reaches ``/rosout``; if it is not (the context was
        shut down by other means), the caller logs the verdict once the node is gone.
        """
        s = self.world.status()
        result = {
            "maze": self.world.maze.name,
            "maze_scale": self.maze_scale,
            "robot": self.robot.name,
            "reached": s.reached,
            "fell": s.fell,
            "interrupted": interrupted and not s.done,
            "time": round(s.time, 3),
            "fitness": s.fitness,
            "final_distance": s.distance,
            "initial_distance": s.initial_distance,
            "episode_time": s.episode_time,
            "mode": self.mode,
            "trajectory": self.trajectory,
            "command_times": self.command_times,
            "wall_seconds": None
            if self.loop_start is None
            else (time.monotonic() - self.loop_start),
        }
        if self.result_file:
            atomic_write_text(self.result_file, json.dumps(result))
        if self.context.ok():
            self.get_logger().info(f"{episode_verdict(result)}; fitness {s.fitness:.3f}")
        return result


def robot_maze(name: str, scale: float, footprint_radius: float, robot: str):
    """``(maze, factor, warning)``: the maze ``name`` scaled to fit the robot, as offline.

    ``scale`` 0: the smallest factor by which the robot fits (1.0 if it fits as it is), with
    the warning line offline runs print; else this factor (a controller's recorded one), as
    it is and without a warning (:func:`sim_bridge.maze_fit.load_fitted_maze`, docs/design.md
    section 21). ``footprint_radius`` in m.

    Raises:
        StartupError: the maze does not load, ``scale`` is in (0, 1), or no factor fits
            (one line naming the parameter).
    """
    from sim_bridge.maze_fit import load_fitted_maze

    if 0.0 < scale < 1.0:
        raise StartupError(
            f"parameter maze_scale must be 0 (fit the robot) or a factor of at least 1, "
            f"got {scale:g}"
        )
    try:
        return load_fitted_maze(name, footprint_radius, robot, scale or None)
    except ConfigError as e:
        raise StartupError(f"parameter maze: {e}") from None


def scaled(factor: float) -> str:
    """`` scaled xF`` for a maze scaled to fit the robot, "" for one as its file has it."""
    return "" if factor == 1.0 else f" scaled x{factor:g}"


def main(argv=None) -> int:
    """Run one episode and exit with its status.

    0 when it ran (or was interrupted), 2 if it cannot start, 1 when another graph shares
    its topics in lockstep (no result is written).
    """
    status = init_ros(argv)
    if status is not None:
        return status
    node, result = None, None
    try:
        node = SimBridgeNode()
        if node.mode == "lockstep":
            node.run_lockstep()
        else:
            node.run_realtime()
        result = node.finish(interrupted=stop_requested())
    except StartupError as e:
        if not e.logged:
            print(f"error: {e}", file=sys.stderr)
        return 2
    except SharedGraphError as e:
        node.get_logger().error(f"lockstep stopped: {e}")
        return 1
    except Exception as e:
        if not isinstance(e, rclpy.executors.ExternalShutdownException) and not stop_requested():
            raise
        if node is not None:  # stopped by a signal, maybe as the context went away
            result = node.finish(interrupted=True)
    except KeyboardInterrupt:
        if node is not None:
            result = node.finish(interrupted=True)
    finally:
        quiet_teardown()
        if node is not None:
            node.world.close()
            logged = node.context.ok()
            node.destroy_node()
            if result is not None and not logged:
                # The node is gone, so this reaches the console and the log file only.
                rclpy.logging.get_logger("sim_bridge").info(
                    f"{episode_verdict(result)}; fitness {result['fitness']:.3f}"
                )
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
