"""Loading neat-python settings files for a task's inputs and outputs."""

from __future__ import annotations

import configparser
import io
import os
import tempfile
from pathlib import Path

import neat

from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.network import ACTIVATIONS, AGGREGATIONS
from offline_evolution.arbitrator.neat_classes import EvoRBCGenome, TargetSpeciesSet

GENOME_SECTION = EvoRBCGenome.__name__


def default_neat_file(robot: str) -> Path:
    """The shipped NEAT settings for ``robot``'s family."""
    family = "hexapod" if robot == "hexapod" else "4ws"
    return config_dir() / "neat" / f"{family}.ini"


def load_neat_config(path: str | os.PathLike, num_inputs: int, num_outputs: int) -> neat.Config:
    """neat-python's Config from ``path`` with the task's numbers of inputs and outputs.

    Raises:
        ConfigError: one line naming the file and the problem (missing file, bad syntax,
            unknown or missing setting, settings the compiled networks cannot run).
    """
    source = str(path)
    parser = configparser.ConfigParser()
    try:
        with open(path, encoding="utf-8") as f:
            parser.read_file(f)
    except FileNotFoundError:
        raise ConfigError(f"{source}: no such NEAT settings file") from None
    except (OSError, UnicodeDecodeError, configparser.Error) as e:
        first = str(e).strip().splitlines()[0]
        raise ConfigError(f"{source}: not a valid NEAT settings file ({first})") from None
    if not parser.has_section(GENOME_SECTION):
        raise ConfigError(
            f"{source}: missing section [{GENOME_SECTION}] (evorbc's genome "
            "class; see config/neat/4ws.ini)"
        )
    parser[GENOME_SECTION]["num_inputs"] = str(num_inputs)
    parser[GENOME_SECTION]["num_outputs"] = str(num_outputs)
    buf = io.StringIO()
    parser.write(buf)
    # neat-python reads settings only from a file name.
    fd, tmp = tempfile.mkstemp(suffix=".ini")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(buf.getvalue())
        config = neat.Config(
            EvoRBCGenome, neat.DefaultReproduction, TargetSpeciesSet, neat.DefaultStagnation, tmp
        )
    except Exception as e:  # neat-python raises bare RuntimeError/NameError/... on bad input
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise ConfigError(f"{source}: {first}") from None
    finally:
        os.unlink(tmp)
    g = config.genome_config
    if not g.feed_forward:
        raise ConfigError(f"{source}: feed_forward must be True (arbitrators are feed-forward)")
    for option, known, what in (
        (g.activation_options, ACTIVATIONS, "activation"),
        (g.aggregation_options, AGGREGATIONS, "aggregation"),
    ):
        for name in option:
            if name not in known:
                raise ConfigError(
                    f"{source}: {what} {name!r} is not supported; use one of {', '.join(known)}"
                )
    return config
