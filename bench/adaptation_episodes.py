"""Measure: what adaptation does to the shipped 4ws-5 controller on the intact robot.

Runs the controller in a closed loop made of the ROS graph's pure code without ROS: the
bridge's world (the 4WS model and PyBullet's walls and laser), the laser node's
rangefinder readings, the radar node's goal readings, :class:`evorbc_ros.arbitration.Controller`
and the executor's wheel commands (speed through the wheel radius and back, as the
lockstep graph sends it). With adaptation off this is what the lockstep graph does, and
the script checks each episode's outcome against the offline replay's (the numba kernel).
Then the same episodes with adaptation on: with the settled outcomes as expected
(:func:`sim_bridge.four_ws.steady.settled_outcomes`), with the recorded ones (what the
arbitrator node has today), and matching by point instead of by outcome. It prints reach
counts, mean time to the target, the observations taken and the share of cycles whose
choice differed from the unadapted run's.

Episodes: the paper's five mazes of the controller's task, from the nominal start and
``--starts`` random starts per maze (seed ``--seed``).

``--steering F`` makes the robot differ from its model in the simplest way: every wheel
steers to ``F`` times its commanded angle (a mismatch of this script's, not one of the
damage sets of ``config/perturbations/``); the replay check is then skipped.

    python bench/adaptation_episodes.py [--starts 4] [--seed 1] [--steering 1.0]
"""

from __future__ import annotations

import math

import numpy as np
from adaptation_observations import arguments

from evorbc_ros.adaptation import AdaptationSettings
from evorbc_ros.arbitration import Controller
from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_arbitrator
from evorbc_ros.goal import GoalInputs
from evorbc_ros.laser import LaserToRangefinders
from offline_evolution.maze_task.base import MazeTaskSettings
from offline_evolution.maze_task.replay import replay
from offline_evolution.maze_task.task import make_task
from sim_bridge.four_ws.motion import speed_through_wheels
from sim_bridge.four_ws.robot import FourWSRobot
from sim_bridge.four_ws.steady import settled_outcomes
from sim_bridge.four_ws.world import FourWSWorld
from sim_bridge.world import LaserConfig


def episode(controller, maze, start, episode_time, robot, steering=1.0):
    """One episode: (reached, seconds, choices, observations)."""
    layout = controller.spec.sensors
    laser = LaserConfig()
    rangefinders = LaserToRangefinders(layout.rangefinders)
    goal = GoalInputs(layout)
    world = FourWSWorld(maze, robot.name, tuple(start), episode_time, laser)
    controller.reset()
    if controller.adaptation is not None:
        controller.adaptation.reset()
    choices = []
    r = robot.geometry.wheel_radius
    try:
        for cycle in range(round(episode_time / world.dt)):
            stamp = cycle * 100_000_000
            x, y, h = world.pose
            ranges = world.scan()
            readings = np.concatenate(
                [
                    rangefinders.readings(
                        laser.angle_min, laser.increment, ranges, laser.range_min, laser.range_max
                    ),
                    goal.readings(x, y, h, *maze.target, stamp_ns=stamp),
                ]
            )
            controller.put_pose(stamp, x, y, h)
            genes, row = controller.step(readings)
            choices.append(int(row[4]))
            if len(genes):
                command = robot.commands(genes[None, :])[0]
                command[0] = speed_through_wheels(command[0], r)
                command[1:] *= steering
            else:
                command = np.zeros(5)
                command[1:] = world.state[0, 4:8]  # stop, wheels where they are
            world.step(command, r)
            if world.reached:
                break
        status = world.status()
        seen = controller.adaptation_state().get("observations", 0)
        return status.reached, world.time, choices, seen
    finally:
        world.close()


def main() -> None:
    """Print the comparison."""
    args = arguments(__doc__, "starts", 4, steering=1.0)
    arb = ArbitratorFile.load(default_arbitrator("4ws-5"))
    task = make_task(MazeTaskSettings.from_dict(arb.evolution["task"], "shipped"), "4ws-5")
    starts = [task.nominal_starts()]
    rng = np.random.default_rng(args.seed)
    starts += [task.sample_starts(rng) for _ in range(args.starts)]
    starts = np.concatenate(starts)
    controller = Controller()
    rep = controller.repertoire
    try:
        outcomes, _ = replay(arb, task, starts, rep)
    finally:
        task.close()
    robot = FourWSRobot("4ws-5")
    settled = settled_outcomes(robot.commands(rep.genes), robot.limits, rep.eval_time)
    variants = {
        "off": None,
        "on": (settled, "outcome"),
        "on, recorded expected": (None, "outcome"),
        "on, match point": (settled, "point"),
    }
    baseline = None
    episode_time = task.settings.episode_time
    print(
        f"{len(starts)} episodes (5 mazes x (nominal + {args.starts} random starts)), "
        f"steering x {args.steering}"
    )
    for name, expected in variants.items():
        if expected is None:
            controller.disable_adaptation()
        else:
            expected, match = expected
            controller.enable_adaptation(AdaptationSettings(match=match), expected)
        results = [
            episode(controller, task.mazes[int(s[0])], s[1:], episode_time, robot, args.steering)
            for s in starts
        ]
        reached = [r[0] for r in results]
        times = [r[1] for r in results if r[0]]
        line = (
            f"{name:24s} reached {sum(reached)}/{len(results)}, mean time "
            f"{np.mean(times) if times else math.nan:.1f} s, observations per episode "
            f"{np.mean([r[3] for r in results]):.1f}"
        )
        if baseline is None and args.steering == 1.0:
            baseline = results
            same = sum(
                r[0] == o.reached and abs(r[1] - o.time) < 1e-6
                for r, o in zip(results, outcomes, strict=True)
            )
            line += f"; same outcome as the offline replay: {same}/{len(results)}"
        elif baseline is None:
            baseline = results
        else:
            differ = [
                sum(a != b for a, b in zip(r[2], b0[2], strict=False))
                / max(min(len(r[2]), len(b0[2])), 1)
                for r, b0 in zip(results, baseline, strict=True)
            ]
            line += f"; choices differing from off: {100 * np.mean(differ):.1f} %"
        print(line, flush=True)


if __name__ == "__main__":
    main()
