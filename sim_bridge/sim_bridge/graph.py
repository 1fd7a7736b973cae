"""The simulated graph as data: which nodes, with which parameters, for which robot.

One description serves both ways of bringing the graph up: ``evorbc-sim``
(:mod:`sim_bridge.bringup`, the nodes as plain processes) and ``ros2 launch evorbc_bringup
sim.launch.py`` (a thin wrapper over :func:`graph_from_arguments`). It imports neither
rclpy nor ``launch``, so the launch logic is tested wherever the project's tests run
(docs/design.md section 10).

Both fill in the same defaults: the robot's shipped controller when no arbitrator is given
(its paper-protocol one with ``paper``; none for a 4WS type other than 4ws-5: the
arbitrator node then refuses to start and says how to make one), the robot's maze,
the episode length the controller was evolved with (its file's task), the factor its task
recorded for the maze when the maze was scaled to fit the robot, simulated time for
the four evorbc nodes, each node's parameter file ``config/ros/<node>.yaml``, the
``robot`` parameter on the arbitrator, which refuses a controller for another robot, and
which nodes are lifecycle nodes (the launch file drives their transitions).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from evorbc_ros.adaptation.settled import EXPECTED
from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.defaults import default_arbitrator, paper_arbitrator, ships_controller
from evorbc_ros.robots import registry
from evorbc_ros.robots.registry import DEFAULT_ROBOT
from sim_bridge.bridge_parameters import PARAMETERS

MODES = ("lockstep", "realtime")


@dataclass(frozen=True)
class Argument:
    """A launch argument: name, default (text, as ``name:=value`` gives it) and help."""

    name: str
    default: str
    description: str


#: The arguments of ``sim.launch.py`` (``ros2 launch evorbc_bringup sim.launch.py --show-args``).
ARGUMENTS = (
    Argument(
        "robot",
        DEFAULT_ROBOT,
        f"robot type: {', '.join(registry.names())}; the arbitrator refuses a controller for "
        "another robot",
    ),
    Argument(
        "maze",
        "",
        "maze name (a file of config/mazes, e.g. obstacle) or maze YAML file; "
        "empty: the robot's own (its registration's maze: obstacle for the 4WS robots)",
    ),
    Argument(
        "mode", "lockstep", "lockstep (deterministic, as fast as the graph) or realtime (10 Hz)"
    ),
    Argument("gui", "false", "open the PyBullet window (true or false)"),
    Argument(
        "arbitrator",
        "",
        "arbitrator file (JSON); empty: the one shipped for robot (4ws-5, hexapod and a1 ship one)",
    ),
    Argument(
        "paper",
        "false",
        "true: the paper-protocol controller shipped for robot (trained on the paper's mazes "
        "only) instead of its default one; not with arbitrator",
    ),
    Argument(
        "repertoire",
        "",
        "repertoire file (JSON); empty: the one shipped for the arbitrator's robot",
    ),
    Argument("start", "nominal", "start pose: nominal, random, or 'x,y,heading_deg'"),
    Argument("seed", "0", "seed of a random start and of the perturbed world (integer >= 0)"),
    Argument(
        "perturb",
        "none",
        "perturbation or damage set for the simulated robot: none, a name in "
        "config/perturbations/ or a YAML file (docs/perturbations.md)",
    ),
    Argument(
        "adaptation",
        "false",
        "true: the arbitrator corrects its primitives' outcomes from odometry while driving "
        "(docs/adaptation.md), as evaluate --adapt does offline",
    ),
    Argument(
        "adaptation_expected",
        "recorded",
        "what adaptation compares an observation with: recorded (the repertoire's outcomes) "
        "or settled (read from the settled-outcomes file beside the repertoire), as "
        "evaluate --adapt-expected",
    ),
    Argument(
        "namespace",
        "",
        "namespace of every node and topic (e.g. robot1); /clock stays global",
    ),
    Argument(
        "bag",
        "",
        "record the run's topics into this new rosbag2 folder (MCAP storage); empty: none",
    ),
)

#: What a recorded run holds (``bag``): topic -> message type. The robot's command topics
#: are added, their types learnt from the graph.
RECORDED = {
    "/clock": "rosgraph_msgs/msg/Clock",
    "scan": "sensor_msgs/msg/LaserScan",
    "odom": "nav_msgs/msg/Odometry",
    "goal": "geometry_msgs/msg/PointStamped",
    "joint_states": "sensor_msgs/msg/JointState",
    "evorbc/rangefinders": "std_msgs/msg/Float64MultiArray",
    "evorbc/goal_sectors": "std_msgs/msg/Float64MultiArray",
    "evorbc/primitive": "std_msgs/msg/Float64MultiArray",
    "evorbc/mapping": "std_msgs/msg/Float64MultiArray",
    "/diagnostics": "diagnostic_msgs/msg/DiagnosticArray",
}


@dataclass(frozen=True)
class NodeSpec:
    """One node of the graph.

    Attributes:
        name: node name, and its executable in ``lib/<package>/`` (``ros2 run``).
        package: ``evorbc_ros`` or ``sim_bridge``.
        module: the module ``python -m`` runs (``evorbc-sim``).
        param_file: the shipped parameter file applied first (``config/ros/``).
        parameters: overrides on top of it (empty values are left out: every empty
            default means "none", and the file may set one).
        required: the graph is over when this node exits, whatever its status.
        managed: a lifecycle node (configure, activate; docs/design.md section 9).
    """

    name: str
    package: str
    module: str
    param_file: Path
    parameters: dict = field(default_factory=dict)
    required: bool = False
    managed: bool = False


@dataclass(frozen=True)
class SimGraph:
    """The five nodes of one simulated run, and the namespace they run in ("" for none)."""

    nodes: tuple[NodeSpec, ...]
    namespace: str = ""

    def node(self, name: str) -> NodeSpec:
        """The node called ``name``."""
        return next(n for n in self.nodes if n.name == name)


def shipped_arbitrator(robot: str, paper: bool = False) -> str:
    """The shipped arbitrator file for ``robot``, or "" if none ships for it.

    With ``paper``, its paper-protocol arbitrator (:func:`evorbc_ros.defaults.paper_arbitrator`).
    """
    if not ships_controller(robot):
        return ""
    return str((paper_arbitrator if paper else default_arbitrator)(robot))


def trained_episode_time(arbitrator: str) -> float | None:
    """s, the episode length the controller in ``arbitrator`` was evolved with, if recorded.

    A controller trained with longer episodes than its robot's default (the hexapod's
    generalising controllers: 60 s, docs/generalisation.md) runs as long through the graph
    as offline (``replay`` and ``evaluate`` use the file's task). None for a file that
    records none, or that cannot be read: the arbitrator node reports a bad file itself.
    """
    try:
        value = _recorded(arbitrator)["evolution"]["task"]["episode_time"]
    except (KeyError, TypeError):
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
        return None
    return float(value)


def rangefinder_reach(arbitrator: str) -> float | None:
    """The distance (m) from the body centre at which ``arbitrator``'s rangefinders stop.

    Its sensor layout's mount radius plus range, or None for a file that records no
    rangefinders or cannot be read (the nodes report a bad file themselves).
    """
    try:
        rangefinders = _recorded(arbitrator)["sensors"]["rangefinders"]
        reach = float(rangefinders.get("mount_radius", 0.0)) + float(rangefinders["range"])
    except (KeyError, TypeError, ValueError, AttributeError):
        return None
    return reach if math.isfinite(reach) and reach > 0 else None


def recorded_maze_scale(arbitrator: str, maze: str) -> float | None:
    """The factor ``arbitrator``'s task recorded for ``maze`` (name or file), if it has one.

    An offline run scales a maze its robot does not fit and records the factor with its
    task (``maze_scale``, docs/design.md section 21); replays apply the recorded factor, so
    the graph does too, and drives the very maze of the offline episode. None when the
    task records no factor for this maze (the bridge then fits the maze itself, as an
    offline run without a record does), or the file cannot be read.
    """
    try:
        task = _recorded(arbitrator)["evolution"]["task"]
        mazes, scales = task["mazes"], task["maze_scale"]
    except (KeyError, TypeError):
        return None
    if not (isinstance(mazes, list) and isinstance(scales, list) and len(mazes) == len(scales)):
        return None
    for name, factor in zip(mazes, scales, strict=True):
        number = isinstance(factor, int | float) and not isinstance(factor, bool)
        if number and 1.0 <= factor <= 100.0 and _same_maze(name, maze):
            return float(factor)
    return None


def _same_maze(recorded, maze: str) -> bool:
    """True if a task's maze entry and the graph's ``maze`` name the same maze."""
    if not isinstance(recorded, str):
        return False
    if recorded == maze:
        return True
    from sim_bridge.maze import is_maze_file  # numba-compiled geometry: only when needed

    if not (is_maze_file(recorded) and is_maze_file(maze)):
        return False
    try:
        return os.path.samefile(recorded, maze)
    except OSError:
        return False


def _recorded(arbitrator: str) -> dict:
    """The JSON of the file ``arbitrator`` names; {} if none is named or it cannot be read."""
    if not arbitrator:
        return {}
    try:
        with open(arbitrator, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def laser_range(arbitrator: str) -> dict:
    """The bridge's ``laser_range`` for ``arbitrator``'s rangefinders, where the default is short.

    A kinematic robot's simulated scanner sits at the body centre (2.0 m by default,
    config/ros/sim_bridge.yaml); a rangefinder reads the beam along its axis, less its
    mount radius. Rangefinders that reach farther (a large robot's: 0.6 m mount, 3 m
    range) would read nothing past the scan's end where the offline episode reads a wall,
    and the lockstep run would leave the offline one (docs/design.md section 9).
    """
    reach = rangefinder_reach(arbitrator)
    default = bridge_default("laser_range")
    return {"laser_range": reach} if reach is not None and reach > default else {}


def default_maze(robot: str) -> str:
    """The maze a robot runs in when none is named (its registration's: obstacle for 4WS)."""
    return registry.lookup(robot).maze


def bridge_default(name: str):
    """The simulation bridge's default value of parameter ``name``."""
    return next(p.default for p in PARAMETERS if p.name == name)


def sim_graph(
    robot: str = DEFAULT_ROBOT,
    maze: str = "",
    mode: str = "lockstep",
    gui: bool = False,
    arbitrator: str = "",
    repertoire: str = "",
    start: str = "nominal",
    seed: int = 0,
    perturb: str = "none",
    namespace: str = "",
    result_file: str = "",
    record_file: str = "",
    paper: bool = False,
    bag: str = "",
    maze_scale: float = 0.0,
    adaptation: bool = False,
    adaptation_expected: str = "recorded",
) -> SimGraph:
    """The graph that runs ``arbitrator`` (default: the one shipped for ``robot``) in a maze.

    ``paper`` picks the robot's shipped paper-protocol arbitrator instead of its default.
    ``bag``: a recorder node, started first, records the run into this rosbag2 folder, and
    the bridge holds its first state until the recorder hears every topic.
    ``maze_scale``: the factor the bridge scales the maze by (>= 1); 0: the one the
    controller's task recorded for this maze, else the bridge fits the maze to the robot as
    offline runs do (docs/design.md section 21).
    ``adaptation``: the arbitrator's ``adaptation`` parameter on; the bridge then waits for
    two subscribers of ``odom`` (the radar node's and the arbitrator's; three with a bag,
    the recorder's too), so that in lockstep the arbitrator sees the first pose and the
    episode is the offline one
    (docs/design/adaptation.md). ``adaptation_expected``: the arbitrator's parameter of
    that name (``recorded`` or ``settled``; passed only when not ``recorded``).

    Raises:
        ConfigError: an unknown robot, mode or ``adaptation_expected``, or ``paper`` with
            ``arbitrator`` (one line naming the argument).
    """
    if not registry.known(robot):
        raise ConfigError(f"robot must be one of {', '.join(registry.names())}, got {robot!r}")
    if mode not in MODES:
        raise ConfigError(f"mode must be lockstep or realtime, got {mode!r}")
    if adaptation_expected not in EXPECTED:
        raise ConfigError(
            f"adaptation_expected must be recorded or settled, got {adaptation_expected!r}"
        )
    if paper and arbitrator:
        raise ConfigError(
            "paper cannot be combined with arbitrator: paper picks the paper-protocol "
            "controller shipped for robot"
        )
    arbitrator = arbitrator or shipped_arbitrator(robot, paper)
    maze = maze or default_maze(robot)
    maze_scale = maze_scale or recorded_maze_scale(arbitrator, maze) or ""
    sim_time = {"use_sim_time": True}

    def evorbc(name: str, managed: bool = False, **params) -> NodeSpec:
        module = f"evorbc_ros.nodes.{name}"
        given = _given(sim_time | params)
        return NodeSpec(name, "evorbc_ros", module, param_file(name), given, managed=managed)

    commands = registry.lookup(robot).command_topics
    recorder = NodeSpec(
        "recorder",
        "sim_bridge",
        "sim_bridge.recorder",
        param_file("recorder"),
        {
            "use_sim_time": True,
            "bag": bag,
            "topics": [*RECORDED, *commands],
            "types": [*RECORDED.values(), *[""] * len(commands)],
        },
    )
    ready = {"wait_for_ready": ["recorder/ready"]} if bag else {}
    adapting = {"adaptation": True} if adaptation else {}
    if adaptation_expected != "recorded":  # an intact graph passes the parameters it did
        adapting["adaptation_expected"] = adaptation_expected
    # Lockstep answers each state once: a first scan or odometry lost to a best-effort
    # match still completing would never be answered (docs/design.md section 9).
    inputs = {"input_qos": "reliable"} if mode == "lockstep" else {}
    # A topic named k times needs k subscribers. The recorder's own subscriptions of the
    # waited topics count too: without them in the count, the recorder's subscription
    # alone let the first state go out before the bridge had discovered the radar node's
    # (a DDS announcement lost under load is repeated only 3 s later); the radar node
    # missed the state, and the state sent again after lockstep_timeout was answered
    # twice by the laser node, shifting every later cycle (docs/design.md section 9).
    waited = list(bridge_default("wait_for_subscribers"))
    if adaptation:  # the arbitrator's odom beside the radar node's
        waited.append("odom")
    if bag:
        waited += [t for t in bridge_default("wait_for_subscribers") if t in RECORDED]
    if waited != list(bridge_default("wait_for_subscribers")):
        ready["wait_for_subscribers"] = waited
    return SimGraph(
        (
            *([recorder] if bag else []),
            evorbc("laser_sensor", sensor_layout=arbitrator, **inputs),
            evorbc("radar_sensor", sensor_layout=arbitrator, **inputs),
            evorbc(
                "arbitrator",
                managed=True,
                arbitrator=arbitrator,
                repertoire=repertoire,
                robot=robot,
                record_file=record_file,
                **adapting,
                **inputs,
            ),
            evorbc("primitive_executor", managed=True, robot=robot, lockstep=mode == "lockstep"),
            NodeSpec(
                "sim_bridge",
                "sim_bridge",
                "sim_bridge.bridge_node",
                param_file("sim_bridge"),
                _given(
                    {
                        "robot": robot,
                        "maze": maze,
                        "maze_scale": maze_scale,
                        "mode": mode,
                        "gui": gui,
                        "start": start,
                        "seed": seed,
                        # Only when asked: an intact graph passes no perturb parameter.
                        **({"perturb": perturb} if perturb != "none" else {}),
                        "result_file": result_file,
                        "episode_time": trained_episode_time(arbitrator) or "",
                        **laser_range(arbitrator),
                        **ready,
                    }
                ),
                required=True,
            ),
        ),
        namespace.strip("/"),
    )


def param_file(node: str) -> Path:
    """The shipped parameter file of ``node`` (``config/ros/<node>.yaml``)."""
    return config_dir() / "ros" / f"{node}.yaml"


def _given(params: dict) -> dict:
    """``params`` without empty strings (rcl cannot parse ``-p name:=``)."""
    return {k: v for k, v in params.items() if v != ""}


def graph_from_arguments(values: dict[str, str]) -> SimGraph:
    """The graph for launch arguments given as text (``name:=value``; missing: default).

    Raises:
        ConfigError: one line naming the argument and what it takes.
    """
    given = {a.name: values.get(a.name, a.default) for a in ARGUMENTS}
    gui, paper, adaptation = (_boolean(given, n) for n in ("gui", "paper", "adaptation"))
    try:
        seed = int(given["seed"])
    except ValueError:
        seed = -1
    if seed < 0:
        raise ConfigError(f"argument seed must be an integer >= 0, got {given['seed']!r}")
    try:
        return sim_graph(
            robot=given["robot"],
            maze=given["maze"],
            mode=given["mode"],
            gui=gui,
            arbitrator=given["arbitrator"],
            repertoire=given["repertoire"],
            start=given["start"],
            seed=seed,
            perturb=given["perturb"],
            namespace=given["namespace"],
            paper=paper,
            bag=given["bag"],
            adaptation=adaptation,
            adaptation_expected=given["adaptation_expected"],
        )
    except ConfigError as e:
        raise ConfigError(f"argument {e}") from None


def _boolean(given: dict[str, str], name: str) -> bool:
    """Launch argument ``name`` (``true`` or ``false``, any case) as a bool."""
    value = given[name].strip().lower()
    if value not in ("true", "false"):
        raise ConfigError(f"argument {name} must be true or false, got {given[name]!r}")
    return value == "true"


def exit_ends_graph(node: NodeSpec, returncode: int | None) -> str:
    """Why the graph shuts down when ``node`` exits with ``returncode``; "" if it goes on.

    The bridge's exit ends the episode, whatever its status; any other node failing
    (non-zero status, or killed by a signal) leaves the graph useless: no command or no
    sensor reading would ever come again.
    """
    if returncode is None:
        return ""  # still running
    if node.required:
        how = "the episode is over" if returncode == 0 else f"status {returncode}"
        return f"{node.name} exited ({how})"
    if returncode != 0:
        return f"{node.name} failed (status {returncode}); the graph cannot run without it"
    return ""
