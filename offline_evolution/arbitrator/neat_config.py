"""Loading neat-python settings files for a task's inputs and outputs."""

from __future__ import annotations

import configparser
import io
import math
import os
import reprlib
import tempfile

import neat

from evorbc_ros.config import ConfigError
from evorbc_ros.input_files import SETTINGS_LIMIT, read_regular_text
from evorbc_ros.network import ACTIVATIONS, AGGREGATIONS
from offline_evolution import bounds
from offline_evolution.arbitrator.neat_classes import (
    EvoRBCGenome,
    EvoRBCReproduction,
    TargetSpeciesSet,
)

GENOME_SECTION = EvoRBCGenome.__name__
#: neat-python's ways of connecting a new genome (first word; "partial" takes a fraction).
INITIAL_CONNECTIONS = (
    "unconnected", "fs_neat_nohidden", "fs_neat", "fs_neat_hidden", "full_nodirect", "full",
    "full_direct", "partial_nodirect", "partial", "partial_direct",
)  # fmt: skip
#: species_fitness_func values neat-python's stagnation knows.
SPECIES_FITNESS = ("max", "min", "mean", "median")
#: fitness_criterion values neat-python's population knows.
FITNESS_CRITERIA = ("max", "min", "mean")
#: *_init_type values neat-python's float attributes draw from (others fail mid-run).
INIT_TYPES = ("gaussian", "gauss", "normal", "uniform")
#: Settings that are spreads, powers, counts or weights: a negative one makes neat-python
#: draw from nothing, never stagnate or speciate backwards.
NON_NEGATIVE_SUFFIXES = ("_stdev", "_mutate_power", "_coefficient")
NON_NEGATIVE = ("num_hidden", "species_elitism", "max_stagnation", "elitism")


def load_neat_config(
    path: str | os.PathLike, num_inputs: int, num_outputs: int, pop_size: int | None = None
) -> neat.Config:
    """neat-python's Config from ``path`` with the task's numbers of inputs and outputs.

    ``pop_size`` replaces the file's ``[NEAT] pop_size`` (``--population``); the file's
    other settings must still fit it (species sizes, elitism), checked as for the file's.

    Raises:
        ConfigError: one line naming the file and the problem (missing file, bad syntax,
            unknown or missing setting, settings the compiled networks cannot run).
    """
    source = str(path)
    parser = configparser.ConfigParser()
    text = read_regular_text(path, "NEAT settings", ConfigError, SETTINGS_LIMIT)
    try:
        parser.read_string(text, source)
    except configparser.Error as e:
        first = str(e).strip().splitlines()[0]
        raise ConfigError(f"{source}: not a valid NEAT settings file ({first})") from None
    if not parser.has_section(GENOME_SECTION):
        raise ConfigError(
            f"{source}: missing section [{GENOME_SECTION}] (evorbc's genome "
            "class; see config/neat/4ws.ini)"
        )
    _check_limits(parser[GENOME_SECTION], source)
    if pop_size is not None and parser.has_section("NEAT"):
        parser["NEAT"]["pop_size"] = str(pop_size)
        source = f"{source} with pop_size {pop_size}"
    parser[GENOME_SECTION]["num_inputs"] = str(num_inputs)
    parser[GENOME_SECTION]["num_outputs"] = str(num_outputs)
    # Users write neat-python's section name; the class that reads it is evorbc's.
    if parser.has_section("DefaultReproduction"):
        parser["EvoRBCReproduction"] = dict(parser["DefaultReproduction"])
    buf = io.StringIO()
    parser.write(buf)
    # neat-python reads settings only from a file name.
    fd, tmp = tempfile.mkstemp(suffix=".ini")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(buf.getvalue())
        config = neat.Config(
            EvoRBCGenome, EvoRBCReproduction, TargetSpeciesSet, neat.DefaultStagnation, tmp
        )
    except AssertionError:  # neat-python asserts on an unknown initial_connection
        raise ConfigError(
            f"{source}: initial_connection must be one of {', '.join(INITIAL_CONNECTIONS)}"
        ) from None
    except Exception as e:  # neat-python raises bare RuntimeError/NameError/... on bad input
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise ConfigError(f"{source}: {first}") from None
    finally:
        os.unlink(tmp)
    _check_values(config, parser, source)
    # feed_forward = False evolves recurrent networks, which every evaluator runs with
    # neat-python's RecurrentNetwork semantics (docs/design.md section 8).
    g = config.genome_config
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


def _check_neat_section(config: neat.Config, parser: configparser.ConfigParser, source: str):
    """[NEAT]: a known fitness criterion and a finite threshold (neat-python checks neither).

    Raises:
        ConfigError: ``FILE: [NEAT] key ...`` in one line.
    """
    if config.pop_size > bounds.POP_SIZE:  # docs/design.md section 12
        raise ConfigError(
            f"{source}: [NEAT] pop_size must be at most {bounds.POP_SIZE:,}, got "
            f"{config.pop_size:,}; lower it"
        )
    criterion = parser["NEAT"].get("fitness_criterion", "max").strip()
    if criterion not in FITNESS_CRITERIA:
        raise ConfigError(
            f"{source}: [NEAT] fitness_criterion must be one of {', '.join(FITNESS_CRITERIA)}, "
            f"got {criterion!r}"
        )
    if not math.isfinite(config.fitness_threshold):
        raise ConfigError(
            f"{source}: [NEAT] fitness_threshold must be a finite number, got "
            f"{parser['NEAT'].get('fitness_threshold')}"
        )


def _check_limits(genome: configparser.SectionProxy, source: str) -> None:
    """Refuse a min above its max (neat-python's own message names no key)."""
    for attr in ("bias", "response", "weight"):
        try:
            low = float(genome.get(f"{attr}_min_value", "-inf"))
            high = float(genome.get(f"{attr}_max_value", "inf"))
        except ValueError:
            continue  # not numbers: neat-python names the problem
        if low > high:
            raise ConfigError(
                f"{source}: [{GENOME_SECTION}] {attr}_min_value ({low}) is above "
                f"{attr}_max_value ({high})"
            )


def _check_values(config: neat.Config, parser: configparser.ConfigParser, source: str) -> None:
    """Refuse settings neat-python accepts but that fail later, or that are typos.

    neat-python checks types but not ranges, ignores unknown keys outside [NEAT], and
    reports some problems only generations into a run; each check here names the key.

    Raises:
        ConfigError: ``FILE: [section] key ...`` in one line.
    """
    sections = {
        GENOME_SECTION: config.genome_config,
        "TargetSpeciesSet": config.species_set_config,
        "DefaultStagnation": config.stagnation_config,
        "DefaultReproduction": config.reproduction_config,
    }
    for name, cfg in sections.items():
        known = {p.name for p in cfg._params} | (
            {"crossover_probability"} if name == GENOME_SECTION else set()
        )
        for key, text in parser[name].items():
            where = f"{source}: [{name}] {key}"
            if key not in known:
                raise ConfigError(f"{where} is not a setting of this section")
            try:
                value = float(text)
            except ValueError:
                continue  # words (sigmoid, gaussian, ...): neat-python checked them
            if not math.isfinite(value):
                raise ConfigError(f"{where} must be a finite number, got {reprlib.repr(text)}")
            if key.endswith(("_prob", "_rate", "_probability", "_add")) and not 0 <= value <= 1:
                raise ConfigError(f"{where} is a probability and must be in [0, 1], got {text}")
            if (key.endswith(NON_NEGATIVE_SUFFIXES) or key in NON_NEGATIVE) and value < 0:
                raise ConfigError(f"{where} must be >= 0, got {text}")
        for key in (k for k in parser[name] if k.endswith("_init_type")):
            if getattr(cfg, key, None) not in INIT_TYPES:
                raise ConfigError(
                    f"{source}: [{name}] {key} must be one of {', '.join(INIT_TYPES)}, "
                    f"got {getattr(cfg, key, None)!r}"
                )
    _check_neat_section(config, parser, source)
    g = config.genome_config
    for what, default, known in (
        ("activation", g.activation_default, ACTIVATIONS),
        ("aggregation", g.aggregation_default, AGGREGATIONS),
    ):
        if default not in known and default not in ("random", "none"):
            raise ConfigError(
                f"{source}: [{GENOME_SECTION}] {what}_default {default!r} is not supported; "
                f"use one of {', '.join(known)} (or random)"
            )
    pop, rep, spc = config.pop_size, config.reproduction_config, config.species_set_config
    checks = (
        (pop >= 2, "[NEAT] pop_size must be at least 2", pop),
        (0 <= rep.elitism < pop, "[DefaultReproduction] elitism must be in [0, pop_size)",
         rep.elitism),
        (rep.min_species_size >= 1, "[DefaultReproduction] min_species_size must be >= 1",
         rep.min_species_size),
        (0 < rep.survival_threshold <= 1,
         "[DefaultReproduction] survival_threshold must be in (0, 1]", rep.survival_threshold),
        (spc.compatibility_threshold > 0,
         "[TargetSpeciesSet] compatibility_threshold must be > 0", spc.compatibility_threshold),
        (spc.target_species_count >= 1, "[TargetSpeciesSet] target_species_count must be >= 1",
         spc.target_species_count),
        (spc.threshold_min > 0, "[TargetSpeciesSet] threshold_min must be > 0",
         spc.threshold_min),
        (spc.threshold_step >= 0, "[TargetSpeciesSet] threshold_step must be >= 0",
         spc.threshold_step),
        (config.stagnation_config.max_stagnation >= 1,
         "[DefaultStagnation] max_stagnation must be >= 1 (generations)",
         config.stagnation_config.max_stagnation),
        (config.stagnation_config.species_fitness_func in SPECIES_FITNESS,
         f"[DefaultStagnation] species_fitness_func must be one of {', '.join(SPECIES_FITNESS)}",
         config.stagnation_config.species_fitness_func),
        # Every species keeps at least min_species_size genomes: the target number of
        # species must fit in the population, or reproduction fails mid-run.
        (spc.target_species_count * max(rep.min_species_size, rep.elitism) <= pop,
         "[NEAT] pop_size must hold target_species_count x min_species_size genomes", pop),
    )  # fmt: skip
    for ok, what, value in checks:
        if not ok:
            raise ConfigError(f"{source}: {what}, got {value}")
    # Every new genome starts with them: neat-python takes minutes to create a population
    # with thousands (docs/design.md section 12).
    hidden = config.genome_config.num_hidden
    if hidden > bounds.NUM_HIDDEN:
        raise ConfigError(
            f"{source}: [{GENOME_SECTION}] num_hidden must be at most {bounds.NUM_HIDDEN}, got "
            f"{hidden}; lower it (NEAT adds hidden nodes as it needs them)"
        )
