"""The memory a run needs, estimated from its settings and refused up front if too much.

Settings that would exhaust memory (``samples_per_maze: 100000``, a tiny ``bin_size``, a
day-long ``episode_time`` replayed with its traces) used to end in ``std::bad_alloc`` or a
MemoryError after minutes of work. Each command estimates its largest allocation from its
settings and refuses, in one line that names the setting and what to lower, a run that
would need more than :data:`SHARE` of the machine's physical memory (``os.sysconf``).

The constants are measured, rounded up (bench notes in docs/performance.md): the 4WS
kernel keeps about 350 bytes per episode of a generation (each robot's registration gives
its own figure, ``episode_bytes``), a recorded replay about 100 bytes per control cycle,
a repertoire about 400 bytes per primitive of a batch and ``(parameters + 8) x 8`` bytes
per archive cell.
"""

from __future__ import annotations

import math
import os

from evorbc_ros.config import ConfigError
from evorbc_ros.robots.registry import lookup

#: The share of the machine's physical memory a run may plan to use.
SHARE = 0.5
GIB = 1 << 30
#: Bytes per recorded control cycle of a replay: pose (3), choice (1), outputs; x 1.3
#: for the temporaries of the report.
CYCLE_BYTES_PER_VALUE = 8 * 1.3
#: Bytes per primitive of a MAP-Elites batch (genes, outcome, copies for the archive).
EVALUATION_BYTES = 400
#: Bytes a run needs anyway (Python, numpy, numba, pyribs).
BASE_BYTES = 400 << 20


def machine_memory() -> int:
    """Physical memory of this machine (bytes), from ``os.sysconf``."""
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def _gib(n: float) -> str:
    if n >= 1e18 * GIB:  # settings far beyond any machine (a count of 10**30)
        return "more than 10^18 GiB"
    return f"{n / GIB:.1f} GiB" if n >= GIB / 10 else f"{n / (1 << 20):.0f} MiB"


def check_memory(need: float, what: str, advice: str) -> None:
    """Refuse a run that would need more than :data:`SHARE` of the machine's memory.

    Args:
        need: the estimate, bytes.
        what: where the need comes from, with the setting's file and key.
        advice: what to lower.

    Raises:
        ConfigError: one line with the estimate, the limit and the advice.
    """
    ram = machine_memory()
    limit = SHARE * ram
    if need > limit:
        raise ConfigError(
            f"{what} needs about {_gib(need)} of memory, more than this machine allows a run "
            f"({_gib(limit)}, half of its {_gib(ram)}); {advice}"
        )


#: The shipped value of each setting that multiplies a generation's or a post-evaluation's
#: episodes; the one furthest above its own is named as the cause of an excess.
USUAL = {
    "[NEAT] pop_size": 150,
    "samples_per_maze": 1,
    "training.generated": 10,
    "training.starts": 1,
    "hall_of_fame": 25,  # the post-evaluation's genomes / 3
    "post_samples": 10,
}


def _first_cause(values: dict[str, tuple[str, int]]) -> tuple[str, str, int]:
    """``(source, key, value)`` of the setting furthest above its :data:`USUAL` value.

    Args:
        values: key -> (where it is set, its value).
    """
    key = max(values, key=lambda k: values[k][1] / USUAL[k])
    return values[key][0], key, values[key][1]


def _lower(cause: str, keys: list[str]) -> str:
    """``lower CAUSE, A or B``: what to lower, the cause first."""
    rest = [k for k in keys if k != cause]
    return (
        f"lower {cause}"
        + (f", {', '.join(rest[:-1])}" if len(rest) > 1 else "")
        + (f" or {rest[-1]}" if rest else "")
    )


def check_evolution_memory(
    task,
    pop_size: int,
    robot: str,
    source: str,
    post_candidates: int,
    post_samples: int,
    finalists: int = 0,
    final_samples: int = 0,
    neat_source: str = "the NEAT settings",
    run_source: str = "the run settings",
) -> None:
    """Refuse an evolution whose generation (or post-evaluation) cannot fit in memory.

    The message starts with the setting furthest above its shipped value (:data:`USUAL`),
    where it is set, and says what to lower, that setting first.

    Args:
        task: the :class:`~offline_evolution.maze_task.task.MazeTaskSettings`.
        pop_size: NEAT's population.
        source: the task settings' file, for the message.
        post_candidates: genomes the post-evaluation re-runs (at most 3 x hall_of_fame, plus
            the snapshots of `snapshot_every`).
        post_samples: its draws of samples_per_maze random starts per maze (plus the
            nominal one).
        finalists, final_samples: its second round (``post_finalists``), if any.
        neat_source, run_source: the NEAT and run settings' files, for the message.
    """
    mazes = len(task.mazes)
    per_episode = lookup(robot).episode_bytes
    # Generated training mazes (docs/design.md section 22) add K x S episodes a genome and
    # post_mazes x post_samples to each post-evaluated genome.
    training = task.training
    own = mazes * task.samples_per_maze if training is None or training.task_mazes else 0
    extra = training.generated * training.starts if training is not None else 0
    generation = pop_size * (own + extra)
    post_extra = training.post_mazes * post_samples if training is not None else 0
    # A draw is samples_per_maze starts in each maze; the first round adds the nominal one.
    per_maze = post_samples * task.samples_per_maze + 1
    post = post_candidates * (mazes * per_maze + post_extra)
    where = f"{mazes} mazes x {task.samples_per_maze} starts"
    causes = {
        "[NEAT] pop_size": (neat_source, pop_size),
        "samples_per_maze": (source, task.samples_per_maze),
    }
    if training is not None:
        where = f"({where} + {training.generated} generated mazes x {training.starts})"
        causes["training.generated"] = (source, training.generated)
        causes["training.starts"] = (source, training.starts)
    file, key, value = _first_cause(causes)
    names = [k.replace("[NEAT] ", "") for k in causes]
    check_memory(
        BASE_BYTES + per_episode * generation,
        f"{file}: {key} {value} ({generation:,} episodes a "
        f"generation: {pop_size} genomes x {where})",
        _lower(
            key.replace("[NEAT] ", ""),
            ["samples_per_maze", "the number of mazes", "pop_size", *names[2:]],
        ),
    )
    file, key, value = _first_cause(
        {
            "post_samples": (run_source, post_samples),
            "samples_per_maze": (source, task.samples_per_maze),
            "hall_of_fame": (run_source, post_candidates // 3),  # 3 x hall_of_fame + snapshots
        }
    )
    cause = f"{key} {value}" if key != "hall_of_fame" else "hall_of_fame and snapshot_every"
    check_memory(
        BASE_BYTES + per_episode * post,
        f"{file}: {cause}: the post-evaluation ({post:,} episodes: {post_candidates} "
        f"genomes x {mazes} mazes x {per_maze} starts"
        + (f" + {post_extra} in validation mazes)" if post_extra else ")"),
        _lower(key, ["post_samples", "hall_of_fame", "samples_per_maze"]),
    )
    if finalists and final_samples:  # the second round's starts have no nominal rows
        final_extra = training.post_mazes * final_samples if training is not None else 0
        finalists = min(finalists, post_candidates)
        final_per_maze = final_samples * task.samples_per_maze
        final = finalists * (mazes * final_per_maze + final_extra)
        check_memory(
            BASE_BYTES + per_episode * final,
            f"the post-evaluation's finalists ({final:,} episodes: {finalists} genomes x "
            f"{mazes} mazes x {final_per_maze} starts"
            + (f" + {final_extra} in validation mazes)" if final_extra else ")"),
            "lower post_final_samples or post_finalists",
        )


def replay_bytes(episodes: int, n_cycles: int, n_outputs: int, robot: str) -> float:
    """Bytes of a recorded replay of ``episodes`` episodes of ``n_cycles`` cycles."""
    trace = (n_cycles + 1) * (4 + n_outputs) * CYCLE_BYTES_PER_VALUE
    return BASE_BYTES + episodes * (lookup(robot).episode_bytes + trace)


def check_replay_memory(
    episodes: int, n_cycles: int, n_outputs: int, robot: str, source: str
) -> None:
    """Refuse a replay whose recorded traces cannot fit in memory.

    Args:
        source: where ``episode_time`` came from (the task file or the arbitrator's record).
    """
    check_memory(
        replay_bytes(episodes, n_cycles, n_outputs, robot),
        f"replaying {episodes:,} episodes of {n_cycles:,} control cycles ({source})",
        "lower episode_time, --episodes or the number of mazes",
    )


def repertoire_cells(robot: str, eval_time: float, bin_size: float) -> int:
    """Cells of a repertoire run's archive (grid or CVT: as many), from its settings."""
    speed = lookup(robot).max_speed  # m/s: the archive spans speed x T each way
    half = max(0, math.ceil(speed * eval_time / bin_size - 0.5))
    return (2 * half + 1) ** 2


def check_repertoire_memory(settings, n_parameters: int, name) -> None:
    """Refuse a MAP-Elites run whose archive or batch cannot fit in memory.

    Args:
        settings: the :class:`~offline_evolution.repertoire.settings.MapElitesSettings`.
        name: ``name(key)`` says where a setting came from (``--bin-size`` or
            ``FILE: bin_size``), for the message.
    """
    cells = repertoire_cells(settings.robot, settings.eval_time, settings.bin_size)
    check_memory(
        BASE_BYTES + cells * (n_parameters + 8) * 8,
        f"{name('bin_size')} {settings.bin_size} ({cells:,} archive cells for "
        f"eval_time {settings.eval_time} s)",
        "raise bin_size or lower eval_time",
    )
    check_memory(
        BASE_BYTES + settings.batch_size * (EVALUATION_BYTES + 32 * n_parameters),
        f"{name('batch_size')} {settings.batch_size} (primitives evaluated at once; the "
        "initial batch runs in pieces of this size)",
        "lower batch_size",
    )
