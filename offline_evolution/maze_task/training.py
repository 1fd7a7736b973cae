"""Training on generated mazes: which mazes each generation draws (docs/design.md section 22).

A maze task whose settings hold a ``training`` mapping trains on the generator's mazes
(:mod:`offline_evolution.mazes.generator`) besides, or instead of, its own ``mazes``:

* every generation draws ``generated`` (K) mazes and ``starts`` (S) random starts in each;
  every genome of the generation runs the same episodes (a fair comparison);
* ``pool: 0`` draws *fresh* mazes: maze indices uniform over :data:`FRESH_INDICES` mazes
  of ``maze_seed``, so no two generations share a maze in practice; ``pool: N`` samples K
  of the fixed pool of mazes ``0 .. N-1`` of ``maze_seed`` (generated once, when first
  drawn);
* the draw, the starts and the worlds of ``perturb`` come from the generation's generator
  ``default_rng([run seed, generation])``, so a resumed run draws what an uninterrupted
  one draws;
* the post-selection of the written controller (hall of fame re-evaluation) runs on the
  task's own mazes plus ``post_mazes`` generated mazes of ``maze_seed`` that no pool holds
  (indices from ``pool`` up): validation mazes, not the held-out set;
* the held-out set (generator seed :data:`~offline_evolution.mazes.held_out.HELD_OUT_SEED`)
  is refused: as ``maze_seed``, as the run seed, and as maze files named after it;
* ``distance: path`` scores a missed episode by the shortest path's length to the target
  (the generator's clearance-aware path search) instead of the straight line, in every
  training maze and in the post-selection: ``1 - p_final / p_initial``. Eq. 5 as the
  paper writes it (``euclidean``) rewards closing in across a wall, which a maze's dead
  ends and baffles turn into traps; the path length does not;
* ``serpentine: F`` makes a share F of the training mazes' obstacles serpentines (the
  generator's narrow winding shafts, as in the paper's ``corridors``; the standard mix,
  which the held-out set uses, has none), validation mazes included;
* ``adapt: true`` runs every EvoRBC episode of the run (training, nominal watch and
  post-selection) with the onboard controller's adaptation on, each from the prior, as
  ``evaluate --adapt`` runs them (docs/design/adaptation.md); ``adapt_expected`` is what an
  observation is compared with (``recorded`` or ``settled``, as ``--adapt-expected``);
* ``post_perturb: true`` runs the post-selection's episodes in worlds of ``perturb`` too
  (each start row its own world, drawn from the post-selection's seed streams), so that a
  run trained on a damaged robot writes the controller that reaches best on that robot;
  without it the post-selection runs in the nominal world, as the shipped controllers'
  did;
* ``fall_penalty: P`` subtracts P from the fitness of every episode in which a legged
  robot fell (training, nominal watch and post-selection). Eq. 5 scores a fall by the
  progress made before it, as a time-out, so a controller that falls after going far
  outscores one that walks safely but slower; with P = 1 a fall scores below every
  episode that did not fall and did not lose ground (docs/your-robot.md).

Generated mazes are proven solvable by the generator; a task keeps the last
:data:`CACHE` of them (and their compiled packs, 4WS), so a pool costs its generation once.
"""

from __future__ import annotations

import time
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from evorbc_ros.adaptation.settled import EXPECTED
from evorbc_ros.config import ConfigError, build_settings, setting
from offline_evolution.maze_task.perturbation import NONE, PerturbationSet, load_perturbations
from offline_evolution.mazes.generator import (
    MAX_SERPENTINE,
    check_serpentine,
    generate_maze,
    spec_for_robot,
)
from offline_evolution.mazes.held_out import HELD_OUT_SEED, is_held_out
from offline_evolution.mazes.paths import DistanceGrid
from sim_bridge.maze import Maze

#: Maze indices a fresh draw picks from: with K = 10 mazes over 1000 generations, two
#: draws share a maze with probability about 5e-5.
FRESH_INDICES = 2**40
#: Generated mazes a task keeps (a pool larger than this is generated again as it cycles).
CACHE = 512
#: Path-distance grids a task keeps (about 0.6 MB each for the 4WS mazes).
GRID_CACHE = 128
#: How a missed episode's distance to the target is measured (``training.distance``).
DISTANCES = ("euclidean", "path")
#: What an adapting episode compares an observation with (``training.adapt_expected``,
#: ``evaluate --adapt-expected``; docs/design/adaptation.md).
ADAPT_EXPECTED = EXPECTED
#: Name prefix of training mazes (``train1-000042``): never a held-out maze's ``gen21021-``.
PREFIX = "train"


@dataclass(frozen=True)
class TrainingSettings:
    """The ``training`` mapping of a maze task file (``config/tasks/*.yaml``)."""

    generated: int = setting(doc="generated mazes per genome per generation (K)", minimum=1)
    starts: int = setting(1, doc="random starts per generated maze (S)", minimum=1)
    pool: int = setting(
        0,
        doc="0: fresh mazes every generation; N: K of the fixed pool of mazes 0..N-1",
        minimum=0,
    )
    maze_seed: int = setting(1, doc="generator seed of the training mazes", minimum=0)
    task_mazes: bool = setting(True, doc="also train on the task's mazes")
    perturb: str = setting("none", doc="perturbation set of the training episodes")
    post_mazes: int = setting(10, doc="generated validation mazes in the post-selection", minimum=0)
    distance: str = setting(
        "euclidean", doc="a missed episode's distance to the target: euclidean (eq. 5) or path"
    )
    serpentine: float = setting(
        0.0,
        doc="share of the training mazes' obstacles that are serpentines (narrow winding "
        "shafts as in corridors; 0: the standard mix, the held-out set's)",
        minimum=0.0,
        maximum=MAX_SERPENTINE,
    )
    adapt: bool = setting(
        False, doc="EvoRBC episodes adapt onboard (docs/design/adaptation.md), each from the prior"
    )
    adapt_expected: str = setting(
        "recorded", doc="what an adapting episode compares observations with: recorded or settled"
    )
    post_perturb: bool = setting(
        False, doc="the post-selection's episodes in worlds of perturb too (false: nominal)"
    )
    fall_penalty: float = setting(
        0.0,
        doc="subtracted from a legged episode's fitness when the robot fell (0: eq. 5 alone)",
        minimum=0.0,
        maximum=10.0,
    )

    @classmethod
    def from_dict(cls, values, source: str) -> TrainingSettings:
        """Checked settings from the task file's ``training`` mapping.

        Raises:
            ConfigError: naming ``source`` and the key: a bad value, a pool smaller than
                ``generated``, the held-out seed as ``maze_seed``, an unknown ``perturb``.
        """
        if not isinstance(values, dict):
            raise ConfigError(f"{source}: training must be a mapping of settings")
        where = f"{source}: training"
        s = build_settings(cls, values, where)
        if s.pool and s.pool < s.generated:
            raise ConfigError(
                f"{where}: pool {s.pool} holds fewer mazes than generated {s.generated} "
                "(0 draws fresh mazes)"
            )
        if s.maze_seed == HELD_OUT_SEED:
            raise ConfigError(
                f"{where}: maze_seed {HELD_OUT_SEED} is the held-out mazes' seed, kept for "
                "evaluation (docs/design.md section 21); choose another"
            )
        if s.distance not in DISTANCES:
            raise ConfigError(
                f"{where}: distance {s.distance!r}: expected one of {', '.join(DISTANCES)}"
            )
        if s.adapt_expected not in ADAPT_EXPECTED:
            raise ConfigError(
                f"{where}: adapt_expected {s.adapt_expected!r}: expected one of "
                f"{', '.join(ADAPT_EXPECTED)}"
            )
        try:
            perturbation = load_perturbations(s.perturb)
        except ConfigError as e:
            raise ConfigError(f"{where}: perturb: {e}") from None
        if s.post_perturb and perturbation is NONE:
            raise ConfigError(f"{where}: post_perturb needs a perturb set (perturb is none)")
        return s

    def as_dict(self) -> dict:
        """Plain-data form (recorded in checkpoints and arbitrator files)."""
        return {
            "generated": self.generated,
            "starts": self.starts,
            "pool": self.pool,
            "maze_seed": self.maze_seed,
            "task_mazes": self.task_mazes,
            "perturb": self.perturb,
            "post_mazes": self.post_mazes,
            # Recorded only when set, so that files and checkpoints written before the
            # setting existed keep their exact settings (a resume compares them).
            **({"distance": self.distance} if self.distance != "euclidean" else {}),
            **({"serpentine": self.serpentine} if self.serpentine else {}),
            **({"adapt": True, "adapt_expected": self.adapt_expected} if self.adapt else {}),
            **({"post_perturb": True} if self.post_perturb else {}),
            **({"fall_penalty": self.fall_penalty} if self.fall_penalty else {}),
        }


def check_training(mazes, training: TrainingSettings | None, seed: int, source: str) -> None:
    """Refuse training on held-out mazes (one-line :class:`ConfigError` naming ``source``).

    Args:
        mazes: the task's mazes (:class:`~sim_bridge.maze.Maze`), trained on unless
            ``training.task_mazes`` is false.
        training: the task's generated-maze training, or None.
        seed: the run's seed (it draws the generated mazes' indices).
    """
    if training is None or training.task_mazes:
        for maze in mazes:
            if is_held_out(maze.name):
                raise ConfigError(
                    f"{source}: mazes: {maze.name} is a held-out maze (generator seed "
                    f"{HELD_OUT_SEED}), kept for evaluation; do not train on it"
                )
    if training is not None and seed == HELD_OUT_SEED:
        raise ConfigError(
            f"--seed {seed} is the held-out mazes' seed; training on generated mazes "
            "refuses it (choose another seed)"
        )


class TrainingMazes:
    """The generated mazes a training run draws from (see the module docstring).

    Args:
        settings: the task's ``training``.
        robot: the registered robot the mazes are made for (its size and footprint,
            :func:`~offline_evolution.mazes.generator.spec_for_robot`).

    """

    def __init__(self, settings: TrainingSettings, robot: str):
        self.settings = settings
        self.spec = spec_for_robot(robot)
        check_serpentine(self.spec, settings.serpentine)
        self.perturbation: PerturbationSet = load_perturbations(settings.perturb)
        self._cache: OrderedDict[int, Maze] = OrderedDict()
        #: Path-distance grids by maze name (``distance: path`` only), the last GRID_CACHE.
        self._grids: OrderedDict[str, DistanceGrid] = OrderedDict()
        #: s spent generating and proving mazes in the last :meth:`mazes` call.
        self.generation_seconds = 0.0

    @property
    def perturbed(self) -> bool:
        """True if training episodes run in perturbed worlds."""
        return self.perturbation is not NONE

    def training_indices(self, rng: np.random.Generator) -> np.ndarray:
        """``(K,)`` maze indices of one generation, drawn from ``rng`` (the pool's, or fresh)."""
        s = self.settings
        if s.pool:
            return rng.choice(s.pool, s.generated, replace=False)
        return rng.integers(0, FRESH_INDICES, s.generated)

    def validation_indices(self, rng: np.random.Generator) -> np.ndarray:
        """``(post_mazes,)`` indices of mazes no pool holds, for the post-selection."""
        return rng.integers(self.settings.pool, FRESH_INDICES, self.settings.post_mazes)

    def mazes(self, indices) -> list[Maze]:
        """Mazes ``indices`` of ``maze_seed``, each proven solvable (kept in a cache)."""
        start = time.perf_counter()
        out = []
        for index in map(int, indices):
            maze = self._cache.get(index)
            if maze is None:
                made = generate_maze(
                    self.spec, self.settings.maze_seed, index, PREFIX, self.settings.serpentine
                )
                maze = made.maze
                self._cache[index] = maze
                if len(self._cache) > CACHE:
                    self._cache.popitem(last=False)
                if self.by_path:
                    self._keep_grid(maze.name, made.grid)
            else:
                self._cache.move_to_end(index)
            out.append(maze)
        self.generation_seconds = time.perf_counter() - start
        return out

    @property
    def by_path(self) -> bool:
        """True if a missed episode is scored by path length (``distance: path``)."""
        return self.settings.distance == "path"

    def path_to_go(self, maze: Maze, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Shortest path lengths (m) to ``maze``'s target from points ``x, y (k,)`` in m.

        Generated mazes reuse their proof's field; the task's own mazes (and a generated
        maze whose grid was dropped) are searched once with the generator's margins.
        """
        grid = self._grids.get(maze.name)
        if grid is None:
            from offline_evolution.mazes.paths import distance_grid, solve

            field_ = solve(maze, self.spec.cell, self.spec.margin, self.spec.snap)
            grid = distance_grid(field_)
            self._keep_grid(maze.name, grid)
        else:
            self._grids.move_to_end(maze.name)
        return grid.at(x, y)

    def _keep_grid(self, name: str, grid: DistanceGrid) -> None:
        self._grids[name] = grid
        if len(self._grids) > GRID_CACHE:
            self._grids.popitem(last=False)


__all__ = [
    "CACHE",
    "DISTANCES",
    "FRESH_INDICES",
    "TrainingMazes",
    "TrainingSettings",
    "check_training",
]
