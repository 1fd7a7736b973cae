"""Budgets of a recipe run: ``full`` (the recipe as written) and ``small`` (a quick check).

The small budget runs every step of a recipe with the same code, files and seeds, on a
budget small enough to check the recipe in seconds: a MAP-Elites run of
``SMALL_REPERTOIRE`` evaluations and a NEAT run of ``SMALL_GENERATIONS`` generations of
``SMALL_POPULATION`` genomes, short episodes and a one-draw post-selection. Its settings
are copies of the recipe's files with those keys lowered, written into the run's output
folder (``small-settings/``), so a small run never reads a file the full one would not.
Its outputs are not the shipped files and are not compared with them.
"""

from __future__ import annotations

import configparser
import io
from pathlib import Path

import yaml

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.config import config_dir, load_yaml_mapping
from offline_evolution.arbitrator.settings import load_run_settings
from offline_evolution.gait_design.objective import Budget
from sim_bridge.maze import is_maze_file

BUDGETS = ("full", "small")
#: MAP-Elites: initial batch, batch size and iterations of the small budget.
SMALL_REPERTOIRE = {"initial_batch": 40, "batch_size": 20, "iterations": 1}
SMALL_GENERATIONS = 2
#: The gait design search of the small budget: two Sobol designs and one refinement, each
#: on 3 primitives and one 0.5 s switching episode.
SMALL_DESIGN = Budget(
    gaits=3, accuracy=1, episodes=1, episode_time=0.5, sobol=2, refine=1, validate=1
)
#: Genomes a generation, and the species NEAT aims for: the population must hold
#: target_species_count x min_species_size genomes (2 a species in the shipped files).
SMALL_POPULATION = 6
SMALL_SPECIES = 3
#: s, the longest episode (the legged robots' simulations dominate a small run).
SMALL_EPISODE_TIME = 2.0
#: Run-settings keys of the post-selection and their small values (0 stays 0).
SMALL_SELECTION = {
    "hall_of_fame": 2,
    "post_samples": 1,
    "nominal_watch": 1,
    "snapshot_every": 1,
    "post_finalists": 1,
    "post_final_samples": 1,
}
#: Training keys of a generated-maze task and their small values.
SMALL_TRAINING = {"generated": 1, "post_mazes": 1}


def small_arbitrator_files(
    settings: str, neat: str | None, task: str | None, folder: Path
) -> dict[str, Path]:
    """Small-budget copies of an arbitrator step's run, NEAT and task settings.

    Args:
        settings: the step's run settings file; ``neat`` and ``task`` override its own.
        folder: where the copies go (created).

    Returns:
        ``{"config": run settings, "neat_config": NEAT file, "task": task file}`` (the
        ``ArbitratorRun`` fields).
    """
    folder.mkdir(parents=True, exist_ok=True)
    run = load_run_settings(settings)
    neat_path = Path(neat) if neat else run.neat_path()
    task_path = Path(task) if task else run.task_path()
    data = load_yaml_mapping(settings)
    for key, small in SMALL_SELECTION.items():
        if data.get(key):
            data[key] = min(data[key], small)
    files = {
        "config": folder / "run.yaml",
        "neat_config": folder / "neat.ini",
        "task": folder / "task.yaml",
    }
    # The copies name each other by absolute path: the run settings' are from config/.
    data["neat"], data["task"] = str(files["neat_config"]), str(files["task"])
    atomic_write_text(files["config"], yaml.safe_dump(data, sort_keys=False))
    atomic_write_text(files["neat_config"], _small_neat(neat_path))
    atomic_write_text(files["task"], _small_task(task_path))
    return files


def _small_neat(path: Path) -> str:
    """The NEAT settings of ``path`` with a population of :data:`SMALL_POPULATION`."""
    parser = configparser.ConfigParser()
    parser.read_string(path.read_text(), str(path))
    parser["NEAT"]["pop_size"] = str(min(SMALL_POPULATION, int(parser["NEAT"]["pop_size"])))
    for section in parser.sections():
        if "target_species_count" in parser[section]:
            species = int(parser[section]["target_species_count"])
            parser[section]["target_species_count"] = str(min(species, SMALL_SPECIES))
    buf = io.StringIO()
    parser.write(buf)
    return buf.getvalue()


def portable_task(path: Path) -> dict:
    """The task settings of ``path`` with its paths absolute, for a copy that lies elsewhere."""
    from offline_evolution.maze_task.base import task_file_values

    data = task_file_values(path)
    if isinstance(data.get("sensors"), str):
        data["sensors"] = str(config_dir() / data["sensors"])  # an absolute path stays
    if isinstance(data.get("mazes"), list):
        data["mazes"] = [
            str(Path(m).resolve()) if isinstance(m, str) and is_maze_file(m) else m
            for m in data["mazes"]
        ]
    return data


def _small_task(path: Path) -> str:
    """The task settings of ``path`` with short episodes and few generated mazes."""
    data = portable_task(path)
    data["episode_time"] = min(float(data.get("episode_time", 120.0)), SMALL_EPISODE_TIME)
    training = data.get("training")
    if isinstance(training, dict):
        data["training"] = {
            **training,
            **{k: min(training[k], v) for k, v in SMALL_TRAINING.items() if k in training},
        }
    return yaml.safe_dump(data, sort_keys=False)
