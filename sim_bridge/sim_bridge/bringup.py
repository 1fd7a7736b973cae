"""``evorbc-sim``: bring up the simulated graph as separate processes, without ``launch``.

Starts ``sim_bridge`` and the four evorbc nodes (``laser_sensor``, ``radar_sensor``,
``arbitrator``, ``primitive_executor``) as processes on this machine, runs one maze
episode, prints the result, writes a trajectory picture, and shuts everything down; Ctrl-C
stops the run cleanly (status 130). The nodes and their parameters come from
:mod:`sim_bridge.graph`, which ``ros2 launch evorbc_bringup sim.launch.py`` uses too, so both
bring up the same graph.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from evorbc_ros.adaptation.settled import EXPECTED
from evorbc_ros.arbitration import Controller
from evorbc_ros.arbitrator import ArbitratorError
from evorbc_ros.config import ConfigError
from evorbc_ros.defaults import (
    PAPER_WITH_FILE,
    no_shipped_controller,
    shipped_robots,
    ships_controller,
)
from evorbc_ros.nodes.common import StartupError
from evorbc_ros.repertoire import RepertoireError
from evorbc_ros.robots import registry
from evorbc_ros.robots.adapters import report
from evorbc_ros.robots.registry import DEFAULT_ROBOT
from sim_bridge.bridge_node import SimBridgeNode
from sim_bridge.cli_options import add_arbitrator, add_flag, add_repertoire, add_robot, add_seed
from sim_bridge.cli_support import OneLineParser, check_output_file, integer_in, report_unexpected
from sim_bridge.graph import (
    NodeSpec,
    exit_ends_graph,
    recorded_maze_scale,
    shipped_arbitrator,
    sim_graph,
)
from sim_bridge.maze import Maze, maze_names
from sim_bridge.robots.adapters import check_design
from sim_bridge.verdict import episode_line, episode_verdict

#: Highest ROS_DOMAIN_ID: DDS derives UDP ports from it, and above 232 they pass 65535.
MAX_DOMAIN_ID = 232

#: The evorbc nodes' modules, by node name (tests start single nodes with these).
NODES = {n.name: n.module for n in sim_graph().nodes if n.package == "evorbc_ros"}


def parse_args(argv=None) -> argparse.Namespace:
    """Command-line options of ``evorbc-sim``."""
    p = OneLineParser(
        prog="evorbc-sim",
        description="Run an evolved controller through the ROS 2 graph "
        "against the PyBullet simulation bridge, one maze episode.",
    )
    add_robot(
        p,
        "robot whose shipped controller runs (default: the arbitrator file's, else 4ws-5; "
        f"{', '.join(shipped_robots())} ship one)",
    )
    p.add_argument(
        "--maze",
        default="",
        help=f"maze name ({', '.join(maze_names())}) or file "
        "(default: the robot's own: obstacle for the 4WS robots)",
    )
    add_arbitrator(p, "the shipped one for --robot")
    add_flag(p, "--paper")
    add_repertoire(p, "the shipped one for the arbitrator's robot")
    p.add_argument(
        "--mode",
        choices=("lockstep", "realtime"),
        default="lockstep",
        help="lockstep: deterministic and fast (default); realtime: 10 Hz wall clock",
    )
    p.add_argument("--start", default="nominal", help="nominal, random or 'x,y,heading_deg'")
    add_seed(p, "seed of a random start and of the perturbed world")
    p.add_argument(
        "--perturb",
        default="none",
        metavar="none|NAME|FILE.yaml",
        help="perturbation or damage set for the simulated robot (config/perturbations/: "
        "realistic, 4ws-stuck-steering, hexapod-leg-lost, ...; docs/perturbations.md); one "
        "world drawn from --seed",
    )
    p.add_argument(
        "--adapt",
        action="store_true",
        help="the arbitrator corrects its primitives' outcomes from odometry while driving "
        "(its adaptation parameter; docs/adaptation.md), as evaluate --adapt does offline",
    )
    p.add_argument(
        "--adapt-expected",
        choices=EXPECTED,
        default="recorded",
        help="what adaptation compares an observation with (its adaptation_expected "
        "parameter): the recorded outcomes (default) or the settled ones shipped beside the "
        "repertoire, as evaluate --adapt-expected",
    )
    p.add_argument("--gui", action="store_true", help="open the PyBullet window")
    p.add_argument("--plot", default="", help="trajectory picture (default: <maze>-run.png)")
    p.add_argument("--result", default="", help="also keep the result as JSON here")
    p.add_argument(
        "--domain-id",
        type=integer_in(0, MAX_DOMAIN_ID),
        default=None,
        help=f"ROS_DOMAIN_ID for the graph, 0 to {MAX_DOMAIN_ID} (default: the environment's, "
        "else 0)",
    )
    p.add_argument(
        "--bag",
        default="",
        help="record the run's topics into this new folder, a rosbag2 bag in MCAP storage "
        "(ros2 bag info and Foxglove open it; evorbc-play plays it back)",
    )
    p.add_argument("--quiet", action="store_true", help="only the result line")
    # Not an option: prepare() sets the maze's factor (0 until then: the bridge fits it).
    p.set_defaults(maze_scale=0.0)
    return p.parse_args(argv)


def node_command(
    module: str, params: dict, param_file: Path | None = None, namespace: str = ""
) -> list[str]:
    """``python -P -m module --ros-args [--params-file F] [-r __ns:=/NS] -p k:=v ...``.

    Empty values are left out; ``-p`` overrides win over the file.
    """
    # -P: never import from the current folder (a checkout of the sources; design.md s. 10).
    cmd = [sys.executable, "-P", "-m", module, "--ros-args"]
    if param_file is not None:
        cmd += ["--params-file", str(param_file)]
    if namespace:
        cmd += ["-r", f"__ns:=/{namespace}"]
    for key, value in params.items():
        if value == "":
            continue  # rcl cannot parse an empty override; every empty default means "none"
        text = str(value).lower() if isinstance(value, bool) else str(value)
        cmd += ["-p", f"{key}:={text}"]
    return cmd


class Graph:
    """The processes of one run; stops them all on exit."""

    def __init__(self, env: dict, quiet: bool) -> None:
        self.env = env
        self.quiet = quiet
        self.procs: dict[str, subprocess.Popen] = {}
        self.specs: dict[str, NodeSpec] = {}

    def start(self, spec: NodeSpec, namespace: str = "") -> subprocess.Popen:
        """Start one node; its output is shown unless quiet."""
        out = subprocess.DEVNULL if self.quiet else None
        proc = subprocess.Popen(
            node_command(spec.module, spec.parameters, spec.param_file, namespace),
            env=self.env,
            stdout=out,
            stderr=out,
            start_new_session=True,
        )
        self.procs[spec.name] = proc
        self.specs[spec.name] = spec
        return proc

    def stop(self, timeout: float = 5.0) -> None:
        """SIGINT every node, then SIGKILL whatever is still running after ``timeout``.

        A recorder is stopped last, once the others are gone, so that it takes their last
        messages.
        """
        first = {n: p for n, p in self.procs.items() if n != "recorder"}
        last = {n: p for n, p in self.procs.items() if n == "recorder"}
        for group in (first, last):
            for proc in group.values():
                if proc.poll() is None:
                    proc.send_signal(signal.SIGINT)
            deadline = time.monotonic() + timeout
            for proc in group.values():
                try:
                    proc.wait(max(0.0, deadline - time.monotonic()))
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()


def start_graph(
    graph: Graph, args: argparse.Namespace, robot: str, arb_path: str, result_file: str
) -> subprocess.Popen:
    """Start the four evorbc nodes and then the bridge, which runs the episode."""
    spec = sim_graph(
        robot=robot,
        maze=args.maze,
        mode=args.mode,
        gui=args.gui,
        arbitrator=arb_path,
        repertoire=args.repertoire or "",  # empty: the shipped one
        start=args.start,
        seed=args.seed,
        perturb=args.perturb,
        result_file=result_file,
        bag=args.bag,
        maze_scale=args.maze_scale,
        adaptation=args.adapt,
        adaptation_expected=args.adapt_expected,
    )
    procs = [graph.start(node, spec.namespace) for node in spec.nodes]
    return procs[-1]  # the bridge, started last: it waits for the others anyway


def check_start(start: str, seed: int, maze: Maze, robot: str) -> None:
    """Refuse a ``--start`` the bridge would refuse, or one outside the maze.

    Raises:
        ConfigError: one line naming ``--start``.

    """
    clearance = registry.lookup(robot).footprint_radius
    try:
        # The bridge's own check, so that both refuse the same starts.
        x, y, _ = SimBridgeNode._start_pose(maze, start, seed, clearance, robot)
    except StartupError as e:
        message = str(e)
        if message.startswith("parameter start"):
            message = "--start" + message.removeprefix("parameter start")
        raise ConfigError(message) from None
    # Far outside, no wall is near, so the clearance check passes; the robot would just
    # drive the whole episode in empty space.
    x0, y0, x1, y1 = maze.bounds()
    if not (x0 < x < x1 and y0 < y < y1):
        raise ConfigError(
            f"--start {start}: ({x:.2f}, {y:.2f}) m is outside maze {maze.name}, which spans "
            f"x {x0:.2f} to {x1:.2f} m and y {y0:.2f} to {y1:.2f} m"
        )


def prepare(args: argparse.Namespace) -> tuple[Controller, Maze, str]:
    """Check every file and option before any node starts (a node would fail less clearly).

    Returns:
        The controller the arbitrator node will load, the maze and the picture path.

    """
    if args.paper and args.arbitrator:
        raise ConfigError(PAPER_WITH_FILE)
    if not args.arbitrator and args.robot and not ships_controller(args.robot):
        raise ConfigError(
            f"{no_shipped_controller(args.robot)}, then run "
            "'evorbc-sim --arbitrator a.json --repertoire r.json'"
        )
    arb_path = args.arbitrator or shipped_arbitrator(args.robot or DEFAULT_ROBOT, args.paper)
    controller = Controller(arb_path, args.repertoire)
    arb = controller.spec
    if args.robot and arb.robot != args.robot:
        raise ConfigError(f"{arb_path}: is for robot {arb.robot}, not --robot {args.robot}")
    robot = registry.lookup(arb.robot)
    check_design(robot, controller)  # e.g. the hexapod: the bridge's design and laser
    args.maze = args.maze or robot.maze
    # The maze of the offline episode: scaled by the factor the controller's task recorded,
    # else fitted to the robot as offline runs fit it, with the same warning line.
    from sim_bridge.maze_fit import load_fitted_maze  # scipy: not for --help

    recorded = recorded_maze_scale(arb_path, args.maze)
    maze, args.maze_scale, warning = load_fitted_maze(
        args.maze, robot.footprint_radius, arb.robot, recorded
    )
    if warning:
        report(warning)
    check_start(args.start, args.seed, maze, arb.robot)
    check_perturb(args.perturb, arb.robot)
    plot = args.plot or f"{maze.name}-run.png"
    check_output_file(plot, "--plot", picture=True)
    if args.result:
        check_output_file(args.result, "--result")
    if args.bag:
        check_new_bag(args.bag)
    return controller, maze, plot


#: The families whose bridge is PyBullet's legged robot (they take legged damage).
LEGGED = ("hexapod", "legged")


def check_perturb(name: str, robot: str) -> None:
    """Refuse a ``--perturb`` set that does not load, or whose damage ``robot`` cannot take.

    Raises:
        ConfigError: one line naming ``--perturb``.
    """
    from sim_bridge.perturbation import load_perturbations

    try:
        damage = load_perturbations(name).damage
    except ConfigError as e:
        raise ConfigError(f"--perturb: {e}") from None
    family = registry.lookup(robot).family
    fits = family == "four_ws" if damage and damage.family == "four_ws" else family in LEGGED
    if damage is not None and not fits:
        raise ConfigError(
            f"--perturb {name}: damage {damage.kind} is for {damage.family} robots, not {robot}"
        )


def check_new_bag(path: str) -> None:
    """Refuse a ``--bag`` folder that exists (or an unfinished one), before any node starts.

    Raises:
        ConfigError: one line naming ``--bag``.
    """
    from sim_bridge.rosbag_io import partial_path

    for where in (Path(path), partial_path(path)):
        if where.exists() or where.is_symlink():
            raise ConfigError(f"--bag {path}: {where} exists; name a new folder")
    check_output_file(path, "--bag")  # its folder can be written


def main(argv=None) -> int:
    """Run one episode through the graph.

    Returns 0 if it ran (reached or not), 2 on a bad option, file or setting (one line,
    before any node starts), 1 when a node was refused or died, 130 after Ctrl-C.
    """
    args = parse_args(argv)
    try:
        return run(args)
    except (ConfigError, ArbitratorError, RepertoireError) as e:
        print(f"evorbc-sim: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("evorbc-sim: interrupted", file=sys.stderr)
        return 130
    except Exception as e:
        return report_unexpected("evorbc-sim", e)


def run(args: argparse.Namespace) -> int:
    """Check, bring the graph up, wait for the episode, report and draw it."""
    controller, maze, plot = prepare(args)
    arb, arb_path = controller.spec, controller.arbitrator_path
    if args.result and Path(args.result).exists():
        Path(args.result).unlink()  # never report an earlier run's result as this one's
    env = dict(os.environ)
    env.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    if args.domain_id is not None:
        env["ROS_DOMAIN_ID"] = str(args.domain_id)
    env.setdefault("PYTHONUNBUFFERED", "1")
    with tempfile.TemporaryDirectory() as tmp:
        result_file = args.result or str(Path(tmp) / "result.json")
        graph = Graph(env, args.quiet)
        bridge, interrupted = None, False
        try:
            bridge = start_graph(graph, args, arb.robot, arb_path, result_file)
            if not args.quiet:
                print(
                    f"evorbc-sim: {arb.kind.name} controller {arb_path} in maze {maze.name} "
                    f"({args.mode}), ROS_DOMAIN_ID={env.get('ROS_DOMAIN_ID', '0')}",
                    file=sys.stderr,
                )
            while bridge.poll() is None:
                for name, proc in graph.procs.items():
                    spec = graph.specs[name]
                    reason = "" if spec.required else exit_ends_graph(spec, proc.poll())
                    if reason:  # the graph is useless without this node
                        print(f"evorbc-sim: error: {reason}", file=sys.stderr)
                        return 1
                time.sleep(0.05)
        except KeyboardInterrupt:
            interrupted = True
            # A second Ctrl-C must not cut the shutdown short and leave nodes running.
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            print("\nevorbc-sim: interrupted; stopping the graph", file=sys.stderr)
        finally:
            graph.stop()  # also when anything above failed: no node outlives evorbc-sim
        if bridge is None:
            return 130
        if not Path(result_file).exists() or (bridge.returncode != 0 and not interrupted):
            print(
                "evorbc-sim: error: the simulation bridge ended without a result "
                f"(status {bridge.returncode})",
                file=sys.stderr,
            )
            return 130 if interrupted else 1
        result = json.loads(Path(result_file).read_text())
    verdict = episode_verdict(result)
    fitness = "" if result.get("interrupted") else f", fitness {result['fitness']:.3f}"
    print(f"{episode_line(maze.name, result)} ({args.mode}) -> {plot}")
    if args.bag:
        recorder = graph.procs["recorder"].returncode
        if recorder != 0:
            print(f"evorbc-sim: error: the recorder failed (status {recorder})", file=sys.stderr)
            return 1
        print(f"recorded {args.bag} (evorbc-play {args.bag} --compare plays it back)")
    from sim_bridge.maze_plot import plot_run

    plot_run(
        maze,
        result["trajectory"],
        f"{maze.name} via ROS 2 ({args.mode}): {verdict}{fitness}",
        plot,
        episode_time=result["episode_time"],
    )
    return 130 if interrupted else 0


if __name__ == "__main__":
    sys.exit(main())
