"""Held-out evaluation: one controller on a suite of mazes from many starts, in perturbed worlds.

:func:`evaluate_suite` runs every episode in one batch of the robot's maze task (the 4WS
compiled kernel, or the hexapod's PyBullet workers) and measures, per episode
(docs/design.md section 21):

* **reached**, **fitness** (eq. 5) and **time**;
* **stalled**: at some point :data:`STALL_TIME` (30 s, at most the episode) passed without
  the robot getting closer to the target *along the maze* (the clearance-aware path
  search's distance to the target) by at least :func:`progress_step`;
* **collided**: the robot's footprint came within :data:`CONTACT` of a wall (the 4WS model
  stops a footprint at a wall, so this is touching it; for a legged robot the footprint
  holds its feet);
* **fell**: the legged robot's body tilted past 90 deg.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from offline_evolution.maze_task.base import MazeTaskBase
from offline_evolution.maze_task.perturbation import NONE, PerturbationSet, check_damage
from offline_evolution.maze_task.replay import cycles_run
from offline_evolution.mazes.paths import solve
from sim_bridge.damage import describe, part_names

#: s without progress along the maze that counts as a stall (capped at the episode time).
STALL_TIME = 30.0
#: m: a footprint this close to a wall surface touches it.
CONTACT = 0.005


def progress_step(footprint_radius: float) -> float:
    """Metres of progress along the maze that count: 0.1 m, or the footprint radius."""
    return max(0.1, footprint_radius)


@dataclass(frozen=True)
class SuiteEpisode:
    """One episode of a suite."""

    maze: str
    start: tuple[float, float, float]  # x m, y m, heading rad (after any start error)
    reached: bool
    fitness: float
    time: float  # s until the target, the fall (as replay and the bridge time it), or the end
    final_distance: float  # m, straight line to the target
    end: tuple[float, float, float]  # the last pose: x m, y m, heading rad (maze frame)
    stalled: bool
    collided: bool
    contact_share: float  # share of the episode's poses touching a wall
    fell: bool
    damage: str = ""  # the episode's damage (docs/perturbations.md), "" when intact
    damaged_part: str = ""  # the wheel, leg or side it hit

    def as_dict(self) -> dict:
        """Plain-data form (JSON); ``damage`` only for a damaged episode."""
        return {
            "maze": self.maze,
            "start": [round(v, 6) for v in self.start],
            "reached": self.reached,
            "fitness": self.fitness,
            "time": round(self.time, 3),
            "final_distance": self.final_distance,
            "end": [round(v, 6) for v in self.end],
            "stalled": self.stalled,
            "collided": self.collided,
            "contact_share": round(self.contact_share, 4),
            "fell": self.fell,
            **({"damage": self.damage} if self.damage else {}),
        }


@dataclass(frozen=True)
class SuiteResult:
    """Every episode of a suite, with the recorded paths."""

    episodes: list[SuiteEpisode]
    paths: list[np.ndarray]  # per episode, (cycles + 1, 3) poses (x m, y m, heading rad)
    perturbation: PerturbationSet
    applied: tuple[str, ...]  # the set's quantities this robot's simulation applied
    not_applicable: tuple[str, ...]  # the set's quantities it cannot model
    # Per episode, (cycles,) the primitive run each cycle and (cycles, n_outputs) the
    # network's outputs (empty when the task records none): what an analysis of the
    # choices needs (bench/adaptation_heldout.py replays the adapting model from them).
    choices: list[np.ndarray] = field(default_factory=list)
    outputs: list[np.ndarray] = field(default_factory=list)

    def per_maze(self) -> list[dict]:
        """Figures per maze, mazes in suite order (see :func:`summarise`)."""
        names = list(dict.fromkeys(e.maze for e in self.episodes))
        return [summarise([e for e in self.episodes if e.maze == n], n) for n in names]

    def overall(self) -> dict:
        """Figures over every episode."""
        return summarise(self.episodes, "all")

    def per_damage(self) -> list[dict]:
        """Figures per damaged part (wheel, leg or side), in name order; [] when intact."""
        parts = sorted({e.damaged_part for e in self.episodes if e.damaged_part})
        return [summarise([e for e in self.episodes if e.damaged_part == p], p) for p in parts]


def reach_interval(reached: int, n: int) -> tuple[float, float]:
    """95 % Wilson score interval of a reach rate of ``reached`` in ``n`` (scipy's).

    A rate from 20 starts is only known to about +-19 points (15 of 20: 0.53-0.89), so the
    report gives the interval with every rate (docs/generalisation.md, "The hexapod"). Wilson's
    interval, unlike the normal one, stays inside [0, 1] and is not empty at 0 or n.
    Returns (low, high) shares; (0, 1) for no episodes.
    """
    if n <= 0:
        return 0.0, 1.0
    from scipy.stats import binomtest  # offline only; the evolution extra installs it

    ci = binomtest(reached, n).proportion_ci(confidence_level=0.95, method="wilson")
    return float(ci.low), float(ci.high)


def summarise(episodes: list[SuiteEpisode], name: str) -> dict:
    """Episodes, reached (count, rate, 95 % interval), mean fitness, stalls, collisions, falls."""
    n = len(episodes)
    reached = sum(e.reached for e in episodes)
    return {
        "maze": name,
        "episodes": n,
        "reached": reached,
        "reach_rate": reached / n if n else 0.0,
        "reach_interval": list(reach_interval(reached, n)),
        "mean_fitness": float(np.mean([e.fitness for e in episodes])) if n else 0.0,
        "stalls": sum(e.stalled for e in episodes),
        "collisions": sum(e.collided for e in episodes),
        "falls": sum(e.fell for e in episodes),
    }


def stalled(distance: np.ndarray, window: int, step: float) -> bool:
    """True if some ``window`` cycles passed without the best distance improving by ``step``.

    ``distance``: ``(k,)`` distance to go (m) at each pose (inf: unknown); ``step``: m.
    """
    if len(distance) <= window:
        return False
    d = np.where(np.isfinite(distance), distance, np.nan)
    if np.all(np.isnan(d)):
        return True
    best = np.fmin.accumulate(np.where(np.isnan(d), np.inf, d))
    return bool(np.any(best[:-window] - best[window:] < step))


def _damage(world, k: int, task) -> dict:
    """Start row ``k``'s ``damage`` and ``damaged_part`` fields (none when intact)."""
    if world is None or world.damage is None:
        return {}
    row = world.damage.row(k)
    part, text = describe(row, part_names(row["kind"], tuple(getattr(task, "damage_legs", ()))))
    return {"damage": text, "damaged_part": part}


def evaluate_suite(
    task: MazeTaskBase,
    network,
    controller,
    starts_per_maze: int,
    seed: int,
    perturbation: PerturbationSet = NONE,
    margin: float | None = None,
    cell: float = 0.02,
) -> SuiteResult:
    """Run ``network`` from seeded random starts in each maze, in worlds drawn from a set.

    ``starts_per_maze`` starts in each of the task's mazes; worlds from ``perturbation``.

    Args:
        task: the robot's maze task over the suite (``task.mazes``).
        network: the controller's :class:`~evorbc_ros.network.NetworkSpec`.
        controller: ``task.controller(...)`` for it.
        seed: starts come from ``default_rng([seed, 0])``, worlds from ``[seed, 1]``, so
            the same starts are used with and without perturbations.
        margin, cell: the path search's clearance (m; default: the footprint radius plus
            0.01 m) and grid (m), for the progress measure; 0.02 m cells read progress to
            a cell, well below the 0.1 m that counts.

    Raises:
        ValueError: the set perturbs something but the task takes no perturbations, or
            names a damage the robot's simulation cannot apply.
    """
    rng = np.random.default_rng([seed, 0])
    starts = np.concatenate(
        [
            np.column_stack(
                [
                    np.full(starts_per_maze, k),
                    m.sample_starts(rng, starts_per_maze, task.footprint_radius),
                ]
            )
            for k, m in enumerate(task.mazes)
        ]
    )
    world = None
    takes = tuple(getattr(task, "perturbations_applied", ()))
    wanted = perturbation.perturbed()
    applied = tuple(q for q in wanted if q in takes)
    missing = tuple(q for q in wanted if q not in applied)
    if perturbation is not NONE:
        if not takes:
            raise ValueError("this robot's maze task takes no perturbations")
        check_damage(task, perturbation)
        world = perturbation.draw(np.random.default_rng([seed, 1]), len(starts))
        starts = world.shift_starts(starts, task.mazes, task.footprint_radius)
    result = task.evaluate([network], controller, starts, record=True, world=world)
    margin = task.footprint_radius + 0.01 if margin is None else margin
    snap = margin - task.footprint_radius + 0.01
    fields = [solve(m, cell, margin, snap) for m in task.mazes]
    window = round(min(STALL_TIME, task.settings.episode_time) / task.dt)
    step = progress_step(task.footprint_radius)
    episodes, paths, choices, outputs = [], [], [], []
    for e, row in enumerate(starts):
        k = int(row[0])
        maze, n = task.mazes[k], int(result.cycles[e])
        # A fall ends the episode, though eq. 5 scores it over all its cycles: time it by
        # the cycles run, as replay and the bridge do ("fell after 11.7 s").
        ran = cycles_run(result, e) if result.choice is not None else n
        pose = result.pose[e, : n + 1]
        pose = pose[np.isfinite(pose[:, 0])]  # a legged robot that fell stops its trace early
        xs, ys = pose[:, 0], pose[:, 1]
        to_go = fields[k].to_go(xs, ys)
        touching = maze.clearances(xs, ys) < task.footprint_radius + CONTACT
        episodes.append(
            SuiteEpisode(
                maze=maze.name,
                start=(float(row[1]), float(row[2]), float(row[3])),
                reached=bool(result.reached[e]),
                fitness=float(result.fitness[e]),
                time=ran * task.dt,
                final_distance=float(result.final_distance[e]),
                end=tuple(float(v) for v in pose[-1]),
                stalled=stalled(to_go, window, step),
                collided=bool(touching.any()),
                contact_share=float(touching.mean()),
                fell=bool(result.fell[e]) if result.fell is not None else False,
                **_damage(world, e, task),
            )
        )
        paths.append(pose)
        if result.choice is not None and result.outputs is not None:
            choices.append(result.choice[e, :n])
            outputs.append(result.outputs[e, :n])
    return SuiteResult(episodes, paths, perturbation, applied, missing, choices, outputs)
