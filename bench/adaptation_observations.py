"""Measure: do short executions of 4WS primitives give usable observations?

The 4WS model steps once per 0.1 s control cycle with rate limits (0.04 m/s and 9 deg per
cycle), so what a primitive does in its first cycles depends on the primitive before it.
For the shipped 4ws-5 repertoire this runs, for random pairs (previous primitive held
until settled, then the next held ``k`` cycles), the ``k``-th cycle of the next one,
extends it to the evaluation time ``T`` as an arc (the onboard observation,
:mod:`evorbc_ros.adaptation.online`) and prints its error against the primitive's recorded
outcome (from rest over ``T``) and against its settled outcome
(:func:`sim_bridge.four_ws.steady.settled_outcomes`), as median and 90th percentile, in m
and in % of the repertoire's largest displacement, for ``k`` = 1..10. Then it feeds the same
executions to :class:`~evorbc_ros.adaptation.online.OnlineAdaptation` (default settings,
one cycle per observation) and prints, per ``k``, how often its rule takes the cycle and
the error of what it takes against the settled outcome. It also prints how
often the shipped controller holds a primitive that long in its replays of the paper's
five mazes (nominal starts), which is how many cycles could be observed.

    python bench/adaptation_observations.py [--pairs 2000] [--seed 1]
"""

from __future__ import annotations

import argparse

import numpy as np

from evorbc_ros.adaptation import AdaptationSettings, OnlineAdaptation
from evorbc_ros.adaptation.model import outcome_table
from evorbc_ros.adaptation.motion import extend_arc, relative_motion
from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.repertoire import Repertoire
from sim_bridge.four_ws.motion import HEADING, STATE_SIZE, X, Y, step_robot
from sim_bridge.four_ws.robot import FourWSRobot
from sim_bridge.four_ws.steady import settle_steps, settled_outcomes

NO_WALLS = np.zeros((0, 6))
NO_CANDIDATES = np.zeros(0, dtype=np.int64)


def observation_errors(rep: Repertoire, robot: FourWSRobot, pairs: int, seed: int, cycles: int):
    """``(cycles, pairs, 2, 2)``: position (m) and heading (rad) errors vs recorded, settled."""
    lim = robot.limits
    commands = np.ascontiguousarray(robot.commands(rep.genes))
    recorded = outcome_table(rep.behaviour, rep.heading)
    settled = settled_outcomes(commands, lim, rep.eval_time)
    rng = np.random.default_rng(seed)
    out = np.zeros((cycles, pairs, 2, 2))
    state = np.zeros((1, STATE_SIZE))
    for p in range(pairs):
        before, now = rng.integers(0, len(rep), 2)
        state[:] = 0.0
        for _ in range(settle_steps(lim)):
            step_robot(state, 0, commands[before], lim, NO_WALLS, NO_CANDIDATES)
        for k in range(cycles):
            x0, y0, h0 = state[0, X], state[0, Y], state[0, HEADING]
            step_robot(state, 0, commands[now], lim, NO_WALLS, NO_CANDIDATES)
            step = relative_motion(x0, y0, h0, state[0, X], state[0, Y], state[0, HEADING])
            seen = np.array(extend_arc(*step, lim.dt, rep.eval_time))
            for j, ref in enumerate((recorded[now], settled[now])):
                out[k, p, j] = np.hypot(*(seen[:2] - ref[:2])), abs(seen[2] - ref[2])
    return out, settled, recorded


def rule_check(rep: Repertoire, robot: FourWSRobot, pairs: int, seed: int, cycles: int):
    """Per k: cycles the onboard rule observed, and their errors vs the settled outcome (m)."""
    lim = robot.limits
    commands = np.ascontiguousarray(robot.commands(rep.genes))
    recorded = outcome_table(rep.behaviour, rep.heading)
    settled = settled_outcomes(commands, lim, rep.eval_time)
    adapt = OnlineAdaptation(recorded, rep.eval_time, AdaptationSettings(window=1), settled)
    rng = np.random.default_rng(seed)
    taken = np.zeros(cycles, dtype=int)
    errors: list[list[float]] = [[] for _ in range(cycles)]
    state = np.zeros((1, STATE_SIZE))
    stamp = 0
    for _ in range(pairs):
        before, now = rng.integers(0, len(rep), 2)
        state[:] = 0.0
        adapt.reset()
        plan = [before] * settle_steps(lim) + [now] * (cycles + 1)
        for t, index in enumerate(plan):
            adapt.put_pose(stamp, state[0, X], state[0, Y], state[0, HEADING])
            count = adapt.model.observations
            adapt.before_choice()
            k = t - settle_steps(lim) - 1  # the cycle just measured: now's (k+1)-th
            if adapt.model.observations > count and k >= 0:
                taken[k] += 1
                errors[k].append(float(np.hypot(*adapt.model.residual[adapt.model.used - 1, :2])))
            adapt.after_choice(int(index))
            step_robot(state, 0, commands[index], lim, NO_WALLS, NO_CANDIDATES)
            stamp += round(lim.dt * 1e9)
    return taken, errors


def hold_lengths(rep: Repertoire) -> np.ndarray:
    """Consecutive cycles each choice had been held, over the shipped controller's replays."""
    from offline_evolution.maze_task.base import MazeTaskSettings
    from offline_evolution.maze_task.replay import replay
    from offline_evolution.maze_task.task import make_task

    arb = ArbitratorFile.load(default_arbitrator("4ws-5"))
    task = make_task(MazeTaskSettings.from_dict(arb.evolution["task"], "shipped"), "4ws-5")
    try:
        _, result = replay(arb, task, task.nominal_starts(), rep)
    finally:
        task.close()
    held = []
    for e in range(len(result.choice)):
        choice = result.choice[e, : int(result.cycles[e])]
        run = 0
        for t in range(len(choice)):
            run = run + 1 if t and choice[t] == choice[t - 1] else 1
            held.append(run)
    return np.array(held)


def arguments(doc: str, count: str, default: int, **floats: float) -> argparse.Namespace:
    """The command line: ``--<count> N`` (episodes or pairs), ``--seed`` and ``floats``."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument(f"--{count}", type=int, default=default)
    parser.add_argument("--seed", type=int, default=1)
    for name, value in floats.items():
        parser.add_argument(f"--{name}", type=float, default=value)
    return parser.parse_args()


def main() -> None:
    """Print the tables."""
    args = arguments(__doc__, "pairs", 2000)
    rep = Repertoire.load(default_repertoire("4ws-5"))
    robot = FourWSRobot("4ws-5")
    tau = float(np.max(np.hypot(rep.behaviour[:, 0], rep.behaviour[:, 1])))
    err, settled, recorded = observation_errors(rep, robot, args.pairs, args.seed, 10)
    gap = np.hypot(*(settled[:, :2] - recorded[:, :2]).T)
    print(f"4ws-5 repertoire: {len(rep)} primitives, T = {rep.eval_time} s, tau = {tau:.3f} m")
    print(
        f"settled vs recorded outcome: position median {np.median(gap):.4f} m "
        f"({100 * np.median(gap) / tau:.1f} % of tau), p90 {np.quantile(gap, 0.9):.4f} m; "
        f"heading median {np.median(abs(settled[:, 2] - recorded[:, 2])):.3f} rad"
    )
    print("k-th cycle held, extended to T: error vs recorded | vs settled")
    print("k  pos med m (%tau)  pos p90 m  head med rad | pos med m (%tau)  pos p90 m  head med")
    for k in range(err.shape[0]):
        row = []
        for j in range(2):
            pos, head = err[k, :, j, 0], err[k, :, j, 1]
            row.append(
                f"{np.median(pos):.4f} ({100 * np.median(pos) / tau:4.1f})  "
                f"{np.quantile(pos, 0.9):.4f}  {np.median(head):.3f}"
            )
        print(f"{k + 1:2d} {row[0]} | {row[1]}")
    taken, errors = rule_check(rep, robot, args.pairs, args.seed, 10)
    print("onboard rule (settle_cycles 1, steady_tolerance 0.02): k  taken  err med m  p90  max")
    for k in range(len(taken)):
        e = np.array(errors[k]) if errors[k] else np.zeros(1)
        print(
            f"  {k + 1:2d}  {taken[k] / args.pairs:.3f}  {np.median(e):.4f}  "
            f"{np.quantile(e, 0.9):.4f}  {e.max():.4f}"
        )
    held = hold_lengths(rep)
    print(f"shipped 4ws-5 controller, paper mazes (nominal starts): {len(held)} cycles")
    for s in (0, 1, 2, 3, 4, 5, 7, 9):
        print(f"  cycles whose primitive ran >= {s} cycles before: {np.mean(held > s):.3f}")


if __name__ == "__main__":
    main()
