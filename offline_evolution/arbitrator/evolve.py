"""Arbitrator evolution (EvoRBC) and the standard-NEAT baseline on any task.

One generation: build each genome's network, run every genome from every start in one
call of the task's ``evaluate`` (the 4WS maze task: one batched kernel call,
:mod:`offline_evolution.maze_task.kernel`), assign the mean fitness, then let neat-python
reproduce and speciate. Start poses are new every generation and the same for every genome
of a generation, drawn from a generator seeded by ``(seed, generation)``; so are the
generated mazes of a task that trains on them (``training``, docs/design.md section 22).

The task is anything that implements :class:`~offline_evolution.task_protocol.ArbitratorTask`
(docs/design.md section 20): by default the maze task that ``settings.task`` describes for
``settings.robot``, or a task of the caller's own.

Runs are seeded and deterministic, checkpoint every few generations as JSON (see
:mod:`offline_evolution.arbitrator.neat_state`) and resume to exactly the result of an
uninterrupted run.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import neat
import numpy as np

from evorbc_ros.arbitrator import ArbitratorFile
from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.controller_kinds import ControllerKind, controller_kind
from evorbc_ros.input_files import SETTINGS_LIMIT, read_regular
from evorbc_ros.network import ConnectionSpec, NetworkSpec, NodeSpec
from evorbc_ros.repertoire import Repertoire, RepertoireError
from evorbc_ros.sensors import SensorLayout
from offline_evolution.arbitrator.neat_config import load_neat_config
from offline_evolution.arbitrator.neat_state import (
    genome_from_dict,
    genome_to_dict,
    population_from_dict,
    population_to_dict,
    require,
)
from offline_evolution.arbitrator.post_scores import PostScores, scores_key
from offline_evolution.arbitrator.selection import (
    HallOfFame,
    PostEvaluation,
    final_starts,
    post_evaluate,
    post_evaluation_starts,
    selection_world,
    validation_rows,
)
from offline_evolution.arbitrator.warm_start import network_fingerprint, seed_population
from offline_evolution.checkpoint import VERSION as CHECKPOINT_VERSION
from offline_evolution.checkpoint import (
    CheckpointError,
    Interrupted,
    check_same_robot,
    check_version,
    load_json_checkpoint,
    settings_mismatch,
)
from offline_evolution.maze_task.task import MazeTaskSettings, make_task
from offline_evolution.reporters import CallbackReporter, Reporter, Reporters
from offline_evolution.task_protocol import ArbitratorTask
from sim_bridge.maze import load_named_maze
from sim_bridge.robots.design import check_simulation

CHECKPOINT_KIND = "evorbc-neat-checkpoint"


#: EvolutionSettings fields that only decide which genome is written, never how the
#: population evolves, so they may change when a run resumes from a checkpoint.
SELECTION_ONLY = (
    "post_samples",
    "post_rule",
    "nominal_watch",
    "snapshot_every",
    "post_finalists",
    "post_final_samples",
)
#: Task keys that only decide which genome is written: the generated validation mazes, and
#: their worlds (``post_perturb``), are drawn from the post-evaluation's own seed streams,
#: never during evolution.
TASK_SELECTION_ONLY = ("post_mazes", "post_perturb")
#: Fields that say where an input lies, not what it holds: the NEAT file's contents are
#: checked by ``neat_sha256``, so a run resumes in another checkout or folder.
LOCATION_ONLY = ("neat_file", "initial_network_file")
#: The run's length: nothing before the last generation depends on it (the training draws
#: are seeded by generation, the hall of fame keeps the best and the latest), so an
#: interrupted run may resume with more generations, or fewer than planned if it has not
#: passed them, and gives what a run of that length gives (docs/design.md section 13).
LENGTH_ONLY = ("generations",)


@dataclass(frozen=True)
class EvolutionSettings:
    """Everything that determines an evolution run's result.

    ``kind`` may be given by name; it is kept as its record
    (:mod:`evorbc_ros.controller_kinds`) and written as its name.
    """

    kind: ControllerKind
    robot: str
    generations: int
    seed: int
    neat_file: str
    neat_sha256: str  # the NEAT settings' contents, so an edited file cannot resume
    task: dict
    mapping: str | None = None
    repertoire_fingerprint: str | None = None
    hall_of_fame: int = 25  # genomes kept for the final post-evaluation
    post_samples: int = 10  # post-evaluation draws of the task's random starts
    post_rule: str = "mean"  # how the post-evaluation picks the written genome (selection.RULES)
    # Each generation's best this many genomes are also run from every maze's nominal
    # start; those that reach the target there join the hall of fame (0: none).
    nominal_watch: int = 0
    # The champion of every this-many-th generation joins the hall of fame for good, so the
    # post-evaluation can choose from the whole run (0: none).
    snapshot_every: int = 0
    # The post-evaluation's this-many best candidates (by post_rule) run post_final_samples
    # more draws of the task's random starts, and the rule picks among them over both
    # rounds (0: one round; docs/design.md section 8).
    post_finalists: int = 0
    post_final_samples: int = 0
    # The network the first population is made from (warm_start.py, ``--init-from``): its
    # fingerprint (what a checkpoint compares) and the file it came from (recorded only).
    initial_network: str | None = None
    initial_network_file: str | None = None
    # The population, when it replaces the NEAT file's pop_size (``--population``).
    population: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "kind", controller_kind(self.kind))

    def as_dict(self) -> dict:
        """Plain-data form (checkpoints and arbitrator files)."""
        data = {**dataclasses.asdict(self), "kind": self.kind.name}
        if data["population"] is None:  # the NEAT file's: files stay as they were
            del data["population"]
        return data


@dataclass(frozen=True)
class GenerationStats:
    """Figures of one evaluated generation."""

    generation: int
    best: float  # highest fitness this generation
    mean: float
    best_so_far: float
    species: int
    seconds: float  # wall time of the whole generation
    evaluation_seconds: float  # of which the batched simulation
    best_reached: int  # mazes the generation's best genome reached

    def as_dict(self) -> dict:
        """Plain-data form."""
        return dataclasses.asdict(self)


@dataclass
class EvolutionResult:
    """The outcome of a run.

    ``best_*`` is the genome with the highest training fitness (the paper's figure);
    ``selected_*`` is the hall-of-fame genome that did best in the post-evaluation, the
    one written to the arbitrator file.
    """

    settings: EvolutionSettings
    best_network: NetworkSpec
    best_fitness: float
    best_generation: int
    best_reached: int  # mazes (episodes) the best genome reached in its evaluation
    selected_network: NetworkSpec
    selected_training_fitness: float
    post_evaluation: PostEvaluation
    history: list[GenerationStats]
    seconds: float


def network_spec(genome, config: neat.Config) -> NetworkSpec:
    """A neat-python genome as a :class:`NetworkSpec` (genes kept in their order).

    The network is recurrent when the settings say ``feed_forward = False``: neat-python
    then evolves genomes with cycles, run as its ``RecurrentNetwork`` runs them.
    """
    gc = config.genome_config
    return NetworkSpec(
        input_keys=tuple(gc.input_keys),
        output_keys=tuple(gc.output_keys),
        nodes=tuple(
            NodeSpec(k, float(n.bias), float(n.response), n.activation, n.aggregation)
            for k, n in genome.nodes.items()
        ),
        connections=tuple(
            ConnectionSpec(k[0], k[1], float(c.weight), bool(c.enabled))
            for k, c in genome.connections.items()
        ),
        recurrent=not gc.feed_forward,
    )


def _without_selection(settings: dict) -> dict:
    """``settings`` without the task keys of :data:`TASK_SELECTION_ONLY` (a copy)."""
    task = settings.get("task")
    training = task.get("training") if isinstance(task, dict) else None
    if not isinstance(training, dict):
        return settings
    kept = {k: v for k, v in training.items() if k not in TASK_SELECTION_ONLY}
    return {**settings, "task": {**task, "training": kept}}


def _inputs_by_content(settings: dict) -> dict:
    """``settings`` with the task's sensor and maze files replaced by what they hold (a copy).

    A file's location, like the NEAT file's, never changes what a run does: a run whose
    sensor layout or training maze moved (into ``config/`` to ship its controller, say)
    resumes from its checkpoint if the layout and the mazes are the same. The sensor file
    becomes its layout's fingerprint; each maze entry (a shipped maze's name or a file's
    path) the fingerprint of its walls, start and target, whatever it is called. A file
    that does not load keeps its path, so the comparison then names the path.
    """
    task = settings.get("task")
    if not isinstance(task, dict):
        return settings
    task = dict(task)
    if isinstance(task.get("sensors"), str):
        try:
            layout = SensorLayout.load(config_dir() / task["sensors"])
            task["sensors"] = f"layout {layout.fingerprint()}"
        except (ConfigError, OSError):
            pass
    if isinstance(task.get("mazes"), list):
        task["mazes"] = [_maze_by_content(m) for m in task["mazes"]]
    return {**settings, "task": task}


def _maze_by_content(entry):
    """A task's maze entry as ``maze <fingerprint>``, or as it is if it does not load."""
    if not isinstance(entry, str):
        return entry
    try:
        maze = load_named_maze(entry).to_dict()
    except (ConfigError, OSError, ValueError):
        return entry
    # The name and description say what a maze is called, not what a robot meets in it.
    held = {k: v for k, v in maze.items() if k not in ("name", "description")}
    digest = hashlib.sha256(json.dumps(held, sort_keys=True).encode()).hexdigest()
    return f"maze {digest[:16]}"


def file_sha256(path: str | os.PathLike, what: str = "NEAT settings") -> str:
    """SHA-256 of a settings file's bytes (a regular file, see :mod:`evorbc_ros.input_files`).

    Raises:
        ConfigError: the file is missing, not a regular file or too large.
    """
    return hashlib.sha256(read_regular(path, what, ConfigError, SETTINGS_LIMIT)).hexdigest()


class Evolution:
    """One NEAT run on a task (:class:`~offline_evolution.task_protocol.ArbitratorTask`).

    Args:
        settings: the run; ``settings.task`` is recorded as it is.
        repertoire: the repertoire an EvoRBC arbitrator chooses from.
        workers: processes that run the maze task's episodes (PyBullet robots).
        repertoire_source: how errors name the repertoire (its file).
        task: the task to evolve on; by default the maze task ``settings.task`` describes
            for ``settings.robot``. A task given here stays the caller's to close.
        initial_network: the network ``settings.initial_network`` fingerprints, for a run
            that starts from it (:func:`~offline_evolution.arbitrator.warm_start.
            seed_population`), its inputs numbered for the task's sensor layout. Without
            it such a run can only :meth:`restore` a checkpoint.

    Raises:
        ConfigError: the initial network does not fit the run (or is not the one
            ``settings`` names).

    """

    def __init__(
        self,
        settings: EvolutionSettings,
        repertoire: Repertoire | None = None,
        workers: int | None = None,
        repertoire_source: str = "the repertoire",
        task: ArbitratorTask | None = None,
        initial_network: NetworkSpec | None = None,
    ):
        self.settings = settings
        self.owns_task = task is None
        if task is None:
            task = make_task(MazeTaskSettings(**settings.task), settings.robot, workers)
        self.task = task
        # Held-out mazes refused, generated training mazes set up (maze tasks; a task of
        # the caller's own may have neither).
        start_training = getattr(task, "start_training", None)
        if start_training is not None:
            try:
                start_training(settings.robot, settings.seed)
            except ConfigError:
                self.close()
                raise
        elif settings.task.get("training"):
            self.close()
            raise ConfigError("this task cannot train on generated mazes (no start_training)")
        # The simulated robot (PyBullet robots; None for the 4WS kinematics).
        self.simulation = self.task.describe()
        if settings.kind.uses_repertoire:
            if repertoire is None:
                raise ValueError("EvoRBC evolution needs a repertoire")
            try:
                check_simulation(repertoire, self.simulation, repertoire_source)
            except RepertoireError:
                self.close()
                raise
        n_outputs = settings.kind.n_outputs(len(self.task.parameter_specs))
        self.controller = self.task.controller(settings.kind, repertoire, settings.mapping)
        try:
            self._adapt_episodes(repertoire)
        except ConfigError:
            self.close()
            raise
        self.config = load_neat_config(
            settings.neat_file, self.task.layout.n_inputs, n_outputs, settings.population
        )
        threshold = self.config.species_set_config.compatibility_threshold
        self.population = neat.Population(self.config, seed=settings.seed)
        # A run that starts from a network and is not given it can only continue from a
        # checkpoint (restore() then compares the fingerprints).
        self._needs_restore = settings.initial_network is not None and initial_network is None
        if initial_network is not None:
            try:
                self._start_from(initial_network, threshold)
            except ConfigError:
                self.close()
                raise
        self.history: list[GenerationStats] = []
        self.best: dict | None = None  # genome_to_dict of the best genome ever
        self.best_generation = -1
        self.best_reached = 0  # mazes the best genome reached in its evaluation
        self.hall = HallOfFame(settings.hall_of_fame)
        self._watched: set[int] = set()  # genome keys already run from the nominal starts
        self.post_scores: PostScores | None = None  # the post-evaluation's rows so far
        self.final_scores: PostScores | None = None  # and its finalists' (post_finalists)
        # The task's sensor layout and mazes as this run read them, saved in checkpoints and
        # compared on resume with the files then: a file edited in place is another run; a
        # moved or renamed one is not.
        self._task_by_content = _inputs_by_content(settings.as_dict())["task"]

    def _adapt_episodes(self, repertoire: Repertoire | None) -> None:
        """``training: adapt: true``: every EvoRBC episode of the run adapts onboard.

        The task's adaptation is :func:`~offline_evolution.maze_task.adapting.task_adapting`'s,
        what ``evaluate --adapt`` runs; each episode starts from the prior.

        Raises:
            ConfigError: a standard controller, or a robot whose episodes do not adapt.
        """
        training = self.settings.task.get("training") or {}
        if not training.get("adapt"):
            return
        if not self.settings.kind.uses_repertoire:
            raise ConfigError(
                "training: adapt: adaptation corrects a repertoire; this run evolves a "
                "standard controller"
            )
        if not hasattr(self.task, "adapt"):
            raise ConfigError(
                f"training: adapt: {self.settings.robot}'s episodes do not adapt yet (4WS, "
                "differential-drive and legged robots do; docs/design/adaptation.md)"
            )
        from offline_evolution.maze_task.adapting import task_adapting

        expected = training.get("adapt_expected", "recorded")
        try:
            _, arrays = task_adapting(self.task, repertoire, expected, self.settings.robot)
        except ValueError as e:
            raise ConfigError(f"training: adapt_expected {expected}: {e}") from None
        self.task.adapt(arrays)

    def _start_from(self, network: NetworkSpec, threshold: float) -> None:
        """Make the first population from ``network`` (the one the settings fingerprint)."""
        if network_fingerprint(network) != self.settings.initial_network:
            raise ConfigError(
                "the initial network given is not the one the run settings name "
                f"({self.settings.initial_network_file or 'none'})"
            )
        seed_population(self.population, network, threshold)

    def close(self) -> None:
        """Close the task if this run made it (a task given to it is the caller's)."""
        if self.owns_task:
            self.task.close()

    @property
    def generation(self) -> int:
        """Generations evaluated so far."""
        return self.population.generation

    @property
    def finished(self) -> bool:
        """True once every generation has been evaluated."""
        return self.generation >= self.settings.generations

    def _evaluate(self, genomes, config) -> None:
        """neat-python fitness function: every genome from every start, in one evaluate()."""
        start = time.perf_counter()
        generation = self.population.generation
        specs = [network_spec(g, config) for _, g in genomes]
        rng = np.random.default_rng([self.settings.seed, generation])
        episodes = getattr(self.task, "generation_episodes", None)
        if episodes is None:  # a task of the caller's own: starts only
            starts, world = self.task.sample_starts(rng), None
        else:  # a maze task: with generated mazes and perturbed worlds if it trains on them
            starts, world = episodes(rng)
        if world is None:
            result = self.task.evaluate(specs, self.controller, starts)
        else:
            result = self.task.evaluate(specs, self.controller, starts, world=world)
        fitness = result.fitness.reshape(len(specs), len(starts)).mean(axis=1)
        reached = result.reached.reshape(len(specs), len(starts)).sum(axis=1)
        for (_, genome), f in zip(genomes, fitness, strict=True):
            genome.fitness = float(f)
        # Only the top of a generation can enter the hall: convert just those to dicts.
        ranked = sorted((g for _, g in genomes), key=lambda g: (-g.fitness, g.key))
        self.hall.update([genome_to_dict(g) for g in ranked[: self.hall.size]])
        every = self.settings.snapshot_every
        if every and (generation + 1) % every == 0:
            self.hall.snapshot(genome_to_dict(ranked[0]))
        self._watch_nominal(ranked[: self.settings.nominal_watch], config)
        self._eval_seconds = time.perf_counter() - start
        k = int(np.argmax(fitness))
        if self.best is None or fitness[k] > self.best["fitness"]:
            self.best = genome_to_dict(genomes[k][1])
            self.best_generation = generation
            self.best_reached = int(reached[k])
        self._gen_figures = (float(fitness[k]), float(fitness.mean()), int(reached[k]))

    def _watch_nominal(self, genomes: list, config) -> None:
        """Run genomes not seen before from every nominal start; keep those that reach.

        Training sees one random start per generation, so a genome that walks the whole
        maze from the nominal start can drop out of the top by training fitness before
        the post-evaluation; this keeps it. The starts draw no random numbers, so the
        evolution is the same with or without the watch.
        """
        fresh = [g for g in genomes if g.key not in self._watched]
        if not fresh:
            return
        self._watched.update(g.key for g in fresh)
        starts = self.task.nominal_starts()
        result = self.task.evaluate(
            [network_spec(g, config) for g in fresh], self.controller, starts
        )
        fitness = result.fitness.reshape(len(fresh), len(starts)).mean(axis=1)
        reached = result.reached.reshape(len(fresh), len(starts)).all(axis=1)
        for g, f, ok in zip(fresh, fitness, reached, strict=True):
            if ok:
                self.hall.add_nominal({**genome_to_dict(g), "nominal_fitness": float(f)})

    def step(self) -> GenerationStats:
        """Evaluate the current generation and breed the next one."""
        if self._needs_restore:
            raise ValueError("a run that starts from a network needs it or a checkpoint")
        start = time.perf_counter()
        # A finished run resumed with more generations: its post-evaluation's rows are of
        # another hall of fame now, so they are not kept in the next checkpoints.
        self.post_scores = self.final_scores = None
        generation = self.population.generation
        species = len(self.population.species.species)
        self.population.run(self._evaluate, 1)
        best, mean, reached = self._gen_figures
        stats = GenerationStats(
            generation=generation,
            best=best,
            mean=mean,
            best_so_far=self.best["fitness"],
            species=species,
            seconds=time.perf_counter() - start,
            evaluation_seconds=self._eval_seconds,
            best_reached=reached,
        )
        self.history.append(stats)
        return stats

    def network(self, genome: dict) -> NetworkSpec:
        """A genome dict (as kept in the hall of fame) as a network."""
        return network_spec(genome_from_dict(genome, self.config), self.config)

    def result(
        self,
        seconds: float,
        progress: Callable[[int, int], None] | None = None,
        after_batch: Callable[..., None] | None = None,
        final_progress: Callable[[int, int], None] | None = None,
    ) -> EvolutionResult:
        """Post-evaluate the hall of fame and assemble the run's outcome.

        ``progress``: reports the post-evaluation's episodes as they finish, on a task
        that reports (``MazeTaskBase.progress``: the legged robots'); ignored otherwise.
        ``after_batch``: called as ``(candidates done, candidates)`` after each batch of
        the post-evaluation (:mod:`~offline_evolution.arbitrator.post_scores`), when
        :meth:`save` would keep it; in its finalists' round (``post_finalists``) as
        ``(finalists done, finalists, "finalists")``.
        ``final_progress``: reports the finalists' round's episodes (default ``progress``).
        """
        candidates = self.hall.candidates()
        starts = post_evaluation_starts(self.task, self.settings.seed, self.settings.post_samples)
        starts, world = selection_world(self.task, starts, self.settings.seed)
        key = scores_key(candidates, starts, world)
        if self.post_scores is None or self.post_scores.key != key:
            # none yet, or saved for another hall or other starts (post_samples changed)
            self.post_scores = PostScores(key)
        s = self.settings
        more = None
        if s.post_finalists and s.post_final_samples:
            if self.final_scores is None:
                self.final_scores = PostScores("")  # post_evaluate keys it

            def more() -> tuple[np.ndarray, int, object]:
                extra = final_starts(self.task, s.seed, s.post_final_samples)
                extra, final_world = selection_world(self.task, extra, s.seed, final=True)
                return extra, validation_rows(self.task, s.post_final_samples), final_world

        post = post_evaluate(
            self.task,
            self.controller,
            [self.network(g) for g in candidates],
            starts,
            self.settings.post_rule,
            len(self.task.nominal_starts()),
            validation_rows(self.task, self.settings.post_samples),
            self.post_scores,
            after_batch,
            progress,
            s.post_finalists,
            more,
            self.final_scores,
            final_progress,
            world=world,
        )
        chosen = candidates[post.index]
        return EvolutionResult(
            settings=self.settings,
            best_network=self.network(self.best),
            best_fitness=self.best["fitness"],
            best_generation=self.best_generation,
            best_reached=self.best_reached,
            selected_network=self.network(chosen),
            selected_training_fitness=chosen["fitness"],
            post_evaluation=post,
            history=self.history,
            seconds=seconds,
        )

    # -- checkpoints -------------------------------------------------------------------

    def save(self, path: str | os.PathLike, elapsed: float) -> None:
        """Write a JSON checkpoint between generations (atomically)."""
        data = {
            "kind": CHECKPOINT_KIND,
            "version": CHECKPOINT_VERSION,
            "settings": self.settings.as_dict(),
            "population": population_to_dict(self.population),
            "best": self.best,
            "best_generation": self.best_generation,
            "best_reached": self.best_reached,
            "hall_of_fame": self.hall.to_dict(),
            "history": [h.as_dict() for h in self.history],
            "elapsed": elapsed,
            "simulation": self.simulation,
        }
        data["task_by_content"] = self._task_by_content
        if self.post_scores is not None:  # the finished run's post-evaluation so far
            data["post_scores"] = self.post_scores.to_dict()
        if self.final_scores is not None and self.final_scores.key:
            data["post_final_scores"] = self.final_scores.to_dict()
        atomic_write_text(path, json.dumps(data))

    def restore(self, path: str | os.PathLike) -> float:
        """Continue from a checkpoint of the same settings; returns its elapsed seconds.

        Raises:
            CheckpointError: unreadable, not a NEAT checkpoint (not ``discardable``), or
                another run's, or with contents no run writes (named in the message).
        """
        data = load_json_checkpoint(path)
        if data.get("kind") != CHECKPOINT_KIND:
            raise CheckpointError(f"{path}: not a NEAT evolution checkpoint", discardable=False)
        check_version(data, str(path))
        if not isinstance(data.get("settings"), dict):
            raise CheckpointError(f"{path}: not a usable checkpoint (settings missing)")
        # Selection settings never change the population, and a file's location never
        # changes its contents, so both may change between sessions.
        ignored = SELECTION_ONLY + LOCATION_ONLY + LENGTH_ONLY
        saved = {k: v for k, v in data["settings"].items() if k not in ignored}
        saved.setdefault("initial_network", None)  # absent before 2026-11-27
        recorded = data.get("task_by_content")  # absent in checkpoints before 2026-11-27
        if isinstance(recorded, dict):
            saved = {**saved, "task": recorded}
        else:  # read what the saved paths hold now
            saved = _inputs_by_content(saved)
        now = {k: v for k, v in self.settings.as_dict().items() if k not in ignored}
        saved = _without_selection(saved)
        now = _without_selection({**now, "task": self._task_by_content})
        if saved.get("initial_network") != now.get("initial_network"):
            raise CheckpointError(f"{path}: {_started_elsewhere(data['settings'], now)}")
        mismatch = settings_mismatch(saved, now)
        if mismatch:
            raise CheckpointError(f"{path}: was written by a different run ({mismatch})")
        check_same_robot(path, data.get("simulation"), self.simulation)
        try:
            self.population = population_from_dict(require(data, "population", dict), self.config)
            self._needs_restore = False
            return self._restore_record(data, path)
        except CheckpointError:
            raise
        except (KeyError, TypeError, ValueError) as e:
            problem = str(e) if isinstance(e, ValueError) else repr(e)
            raise CheckpointError(f"{path}: not a usable checkpoint ({problem})") from None

    def _restore_record(self, data: dict, path) -> float:
        """Restore the best genome, hall of fame and history; the run's elapsed seconds."""
        generation = self.generation
        if generation < 0:
            raise ValueError(f"population.generation must be 0 or more, got {generation}")
        if generation > self.settings.generations:
            raise CheckpointError(
                f"{path}: the run is past generation {generation}, so it cannot stop at "
                f"{self.settings.generations}; run it with --generations {generation} or more"
            )
        best = require(data, "best", dict, none_ok=generation == 0)
        if best is not None:
            genome_from_dict(best, self.config, "best.")
            require(best, "fitness", float, "best.")
        self.best = best
        self.best_generation = require(data, "best_generation", int)
        self.best_reached = require(data, "best_reached", int)
        hall = require(data, "hall_of_fame", dict)
        for part in ("top", "recent", "nominal", "snapshots"):
            if part in ("nominal", "snapshots") and part not in hall:
                continue  # written before the nominal watch existed, or without snapshots
            for i, g in enumerate(require(hall, part, list, "hall_of_fame.")):
                genome_from_dict(g, self.config, f"hall_of_fame.{part}[{i}].")
                require(g, "fitness", float, f"hall_of_fame.{part}[{i}].")
                if part == "nominal":
                    require(g, "nominal_fitness", float, f"hall_of_fame.{part}[{i}].")
        size = require(hall, "size", int, "hall_of_fame.")
        if size < 1:
            raise ValueError(f"hall_of_fame.size must be 1 or more, got {size}")
        self.hall = HallOfFame.from_dict(hall)
        history = require(data, "history", list)
        if len(history) != generation:
            raise ValueError(f"history has {len(history)} generations, the population {generation}")
        kinds = {
            f.name: float if f.type == "float" else int for f in dataclasses.fields(GenerationStats)
        }
        for i, h in enumerate(history):
            for key, kind in kinds.items():
                require(h, key, kind, f"history[{i}].")
        self.history = [GenerationStats(**{k: h[k] for k in kinds}) for h in history]
        if "post_scores" in data:  # interrupted in its post-evaluation
            self.post_scores = PostScores.from_dict(require(data, "post_scores", dict))
        if "post_final_scores" in data:  # and in its finalists' round
            where = "post_final_scores."
            self.final_scores = PostScores.from_dict(
                require(data, "post_final_scores", dict), where
            )
        elapsed = float(require(data, "elapsed", float))
        if elapsed < 0:
            raise ValueError(f"elapsed must be 0 s or more, got {elapsed}")
        return elapsed


def evolve(
    settings: EvolutionSettings,
    repertoire: Repertoire | None = None,
    *,
    checkpoint: str | os.PathLike | None = None,
    checkpoint_every: int = 10,
    reporters: Sequence[Reporter] = (),
    should_stop: Callable[[], bool] | None = None,
    workers: int | None = None,
    repertoire_source: str = "the repertoire",
    keep_checkpoint: bool = False,
    task: ArbitratorTask | None = None,
    initial_network: NetworkSpec | None = None,
    **callbacks: Callable | None,
) -> EvolutionResult:
    """Run NEAT on a task to the last generation (exported as ``evolve_arbitrator``).

    Args:
        settings: the run (see :class:`EvolutionSettings`).
        repertoire: the repertoire an EvoRBC arbitrator chooses from.
        checkpoint: resumed from if it exists, written every ``checkpoint_every``
            generations, removed at the end (unless ``keep_checkpoint``).
        reporters: told of the run as it goes (:mod:`offline_evolution.reporters`): a
            resume, every generation's end, the post-evaluation's episodes.
        should_stop: polled after every generation and after every batch of the
            post-evaluation; True saves and raises
            :class:`~offline_evolution.repertoire.map_elites.Interrupted` (a stop asked for
            in the last generation stops after the post-evaluation's first batch).
        workers: processes that run episodes (PyBullet robots; default: every core). The
            result does not depend on it.
        repertoire_source: how errors name the repertoire (its file).
        keep_checkpoint: save the finished run to ``checkpoint`` and keep it, for a caller
            that removes it only once the arbitrator file is safely written; the same
            call then only post-evaluates again, with the rows it saved (seeded: the same
            result).
        task: the task to evolve on (any :class:`~offline_evolution.task_protocol.
            ArbitratorTask`); by default the maze task ``settings.task`` describes for
            ``settings.robot``. A task given here is left open for the caller.
        initial_network: the network a run with ``settings.initial_network`` starts from
            (:mod:`~offline_evolution.arbitrator.warm_start`); a run that resumes from
            ``checkpoint`` only checks its fingerprint (the checkpoint holds the population).
        callbacks: the callbacks it took before reporters, ``progress``, ``on_resume``,
            ``post_progress`` and ``final_progress``: still taken, with a
            DeprecationWarning naming ``reporters``.

    Raises:
        RepertoireError: the repertoire was evolved for another simulated robot.
        CheckpointError: the checkpoint exists but belongs to another run or is corrupt.
        ConfigError: the initial network does not fit the run.
    """
    report = Reporters([*reporters, *_legacy_reporter(callbacks)])
    resuming = checkpoint is not None and os.path.exists(checkpoint)
    given = initial_network
    if resuming and given is not None and network_fingerprint(given) != settings.initial_network:
        raise ConfigError("the initial network given is not the one the run settings name")
    # A resumed population comes from the checkpoint: the network need not seed one.
    seeds = None if resuming else initial_network
    run = Evolution(settings, repertoire, workers, repertoire_source, task, seeds)
    try:
        elapsed = 0.0
        if resuming:
            elapsed = run.restore(checkpoint)
            report.resumed(run.generation)
        start = time.perf_counter() - elapsed
        saved = run.generation
        while not run.finished:
            stats = run.step()
            report.generation_end(stats, settings)
            stop = should_stop is not None and should_stop() and not run.finished
            due = checkpoint is not None and run.generation % max(1, checkpoint_every) == 0
            if checkpoint is not None and (due or stop) and not run.finished:
                run.save(checkpoint, time.perf_counter() - start)
                saved = run.generation
            if stop:
                raise Interrupted(run.generation, _path(checkpoint))
        # The finished population is saved before the post-evaluation, and every batch of
        # it after, so an interruption there loses at most a batch (post_scores.py).
        if checkpoint is not None and saved != run.generation:
            run.save(checkpoint, time.perf_counter() - start)

        def after_batch(done: int, total: int, what: str = "candidates") -> None:
            if checkpoint is not None:
                run.save(checkpoint, time.perf_counter() - start)
            if should_stop is not None and done < total and should_stop():
                during = f"the post-evaluation ({done} of {total} {what} done)"
                raise Interrupted(run.generation, _path(checkpoint), during)

        result = run.result(
            time.perf_counter() - start,
            report.episodes(finalists=False),
            after_batch,
            report.episodes(finalists=True),
        )
        if checkpoint is not None and not keep_checkpoint and os.path.exists(checkpoint):
            os.remove(checkpoint)
        return result
    finally:
        run.close()


#: The callbacks evolve() took before reporters.
_CALLBACKS = ("progress", "on_resume", "post_progress", "final_progress")


def _legacy_reporter(callbacks: dict) -> list[Reporter]:
    """A reporter for the callbacks of the old API, with a DeprecationWarning; none if none."""
    unknown = set(callbacks) - set(_CALLBACKS)
    if unknown:
        raise TypeError(f"evolve() got an unexpected keyword argument {sorted(unknown)[0]!r}")
    if not any(v is not None for v in callbacks.values()):
        return []
    warnings.warn(
        f"evolve({', '.join(sorted(callbacks))}=...) is deprecated: pass "
        "reporters=[...] (offline_evolution.reporters.Reporter)",
        DeprecationWarning,
        stacklevel=3,
    )
    return [CallbackReporter(**callbacks)]


def _started_elsewhere(saved: dict, now: dict) -> str:
    """Why a checkpoint's starting network is not this run's, and what to give instead."""
    fingerprint, source = saved.get("initial_network"), saved.get("initial_network_file")
    if not fingerprint:
        return "was written by a run that started from random networks, not from --init-from"
    started = f"the run started from the network of {source} ({str(fingerprint)[:12]})"
    if now.get("initial_network") is None:
        return f"{started}: give --init-from {source} to resume it"
    return f"{started}, not from the one given"


def _path(checkpoint: str | os.PathLike | None) -> str | None:
    return None if checkpoint is None else str(checkpoint)


def arbitrator_file(
    result: EvolutionResult,
    task: ArbitratorTask,
    repertoire: Repertoire | None = None,
    repertoire_source: str | None = None,
) -> ArbitratorFile:
    """The arbitrator file of a finished run."""
    s = result.settings
    evolution = {
        "seed": s.seed,
        "generations": s.generations,
        "best_fitness": result.best_fitness,
        "best_generation": result.best_generation,
        "best_reached": result.best_reached,
        "selected_training_fitness": result.selected_training_fitness,
        "post_evaluation": {
            **result.post_evaluation.as_dict(),
            "samples_per_maze": s.post_samples,
            "nominal_starts": True,
            "hall_of_fame": s.hall_of_fame,
            "nominal_watch": s.nominal_watch,
            **({"snapshot_every": s.snapshot_every} if s.snapshot_every else {}),
            **(
                {"final_samples_per_maze": s.post_final_samples}
                if result.post_evaluation.finalists
                else {}
            ),
        },
        **(
            {
                "initial_network": {
                    "file": Path(s.initial_network_file).name if s.initial_network_file else None,
                    "fingerprint": s.initial_network,
                }
            }
            if s.initial_network
            else {}
        ),
        "seconds": round(result.seconds, 1),
        "neat_settings": Path(s.neat_file).name,
        "neat_sha256": s.neat_sha256,
        "task": s.task,
        "history": [h.as_dict() for h in result.history],
    }
    if s.population is not None:  # --population: the NEAT file's pop_size was replaced
        evolution["population"] = s.population
    simulation = task.describe()
    if simulation is not None:
        evolution["simulation"] = simulation  # the robot the controller was evolved on
    if s.kind.uses_repertoire:
        return ArbitratorFile(
            kind=s.kind,
            robot=s.robot,
            network=result.selected_network,
            sensors=task.layout,
            mapping=s.mapping,
            control_period=task.dt,
            evolution=evolution,
            repertoire={
                "fingerprint": repertoire.fingerprint(),
                "robot": repertoire.robot,
                "count": len(repertoire),
                "file": Path(repertoire_source).name if repertoire_source else None,
            },
        )
    return ArbitratorFile(
        kind=s.kind,
        robot=s.robot,
        network=result.selected_network,
        sensors=task.layout,
        parameters=task.parameter_specs,
        control_period=task.dt,
        evolution=evolution,
    )
