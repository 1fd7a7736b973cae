"""A neat-python population as plain JSON data, for resume checkpoints.

neat-python's own checkpoints are pickles, and a pickle runs code when loaded, so a
checkpoint file handed over by someone else could run anything. This module writes
everything a run needs to continue exactly where it stopped (genomes with their genes in
order, species, counters, the innovation tracker, the adaptive compatibility threshold
and Python's random state) as JSON, and rebuilds the objects from it.

A checkpoint is a file like any other: before anything is rebuilt, its structure and
types are checked, and a problem is raised as a ``ValueError`` that names the entry
(``population.genomes[3].nodes[0].bias must be a number``).
"""

from __future__ import annotations

import math
import random
from itertools import count

import neat
from neat.attributes import BoolAttribute, FloatAttribute, StringAttribute
from neat.species import Species

from evorbc_ros.limits import NETWORK_CONNECTIONS, NETWORK_NODES
from evorbc_ros.network import NetworkError, topological_order

_KINDS = {int: "a whole number", float: "a number", str: "a string", bool: "true or false"}
_KINDS.update({list: "a list", dict: "an object"})


def require(data: dict, key: str, kind: type, where: str = "", none_ok: bool = False):
    """``data[key]`` if it is of ``kind`` (``float``: any finite number).

    Raises:
        ValueError: ``<where><key> is missing`` or ``... must be <kind>, got <value>``.

    """
    if not isinstance(data, dict):
        raise ValueError(f"{where.rstrip('.') or 'the checkpoint'} must be an object")
    if key not in data:
        raise ValueError(f"{where}{key} is missing")
    value = data[key]
    if value is None and none_ok:
        return None
    if kind is float:
        ok = isinstance(value, (int, float)) and math.isfinite(value)
    else:
        ok = isinstance(value, kind)
    # bool is an int subclass; true/false where a number belongs is a mistake.
    if not ok or (isinstance(value, bool) and kind is not bool):
        raise ValueError(f"{where}{key} must be {_KINDS[kind]}, got {value!r:.40}")
    return value


def _attribute_kind(attribute) -> type:
    kinds = {BoolAttribute: bool, FloatAttribute: float, StringAttribute: str}
    return next(k for cls, k in kinds.items() if isinstance(attribute, cls))


def check_genome_dict(data: dict, config: neat.Config, where: str = "genome.") -> None:
    """Check that ``data`` is a genome :func:`genome_to_dict` could have written.

    Raises:
        ValueError: naming the first entry that is missing, of the wrong type, or an
            activation or aggregation the NEAT settings do not offer.

    """
    gc = config.genome_config
    require(data, "key", int, where)
    require(data, "fitness", float, where, none_ok=True)
    for limit, part in ((NETWORK_NODES, "nodes"), (NETWORK_CONNECTIONS, "connections")):
        problem = limit.problem(len(require(data, part, list, where)), f"in {where}{part}")
        if problem:
            raise ValueError(problem)
    nodes = set()
    for part, gene_type in (("nodes", gc.node_gene_type), ("connections", gc.connection_gene_type)):
        for i, gene in enumerate(require(data, part, list, where)):
            w = f"{where}{part}[{i}]."
            if part == "nodes":
                nodes.add(require(gene, "key", int, w))
            else:
                key = require(gene, "key", list, w)
                if len(key) != 2 or not all(k in nodes or k in gc.input_keys for k in key):
                    raise ValueError(f"{w}key must join two nodes of the genome, got {key}")
                require(gene, "innovation", int, w)
            for attribute in gene_type._gene_attributes:
                value = require(gene, attribute.name, _attribute_kind(attribute), w)
                if isinstance(attribute, StringAttribute):
                    options = getattr(gc, attribute.options_name)
                    if value not in options:
                        raise ValueError(f"{w}{attribute.name} must be one of {options}")
    missing = set(gc.output_keys) - nodes
    if missing:
        raise ValueError(f"{where}nodes lacks the output nodes {sorted(missing)}")
    if gc.feed_forward:
        # neat-python never adds a connection that closes a cycle to a feed-forward
        # genome (disabled ones included: mutation may enable them again).
        edges = [tuple(c["key"]) for c in data["connections"]]
        try:
            topological_order(nodes, edges)
        except NetworkError as e:
            raise ValueError(f"{where}connections: {e}") from None


def genome_to_dict(genome) -> dict:
    """A genome's genes, in their dict order, plus key and fitness."""

    def gene(g) -> dict:
        out = {"key": list(g.key) if isinstance(g.key, tuple) else g.key}
        if hasattr(g, "innovation"):
            out["innovation"] = g.innovation
        for attribute in g._gene_attributes:
            out[attribute.name] = getattr(g, attribute.name)
        return out

    return {
        "key": genome.key,
        "fitness": genome.fitness,
        "nodes": [gene(n) for n in genome.nodes.values()],
        "connections": [gene(c) for c in genome.connections.values()],
    }


def genome_from_dict(data: dict, config: neat.Config, where: str = "genome."):
    """Rebuild a genome written by :func:`genome_to_dict`.

    Raises:
        ValueError: ``data`` is not such a genome (see :func:`check_genome_dict`).

    """
    check_genome_dict(data, config, where)
    gc = config.genome_config
    genome = config.genome_type(data["key"])
    genome.fitness = data["fitness"]
    for n in data["nodes"]:
        node = gc.node_gene_type(n["key"])
        for attribute in node._gene_attributes:
            setattr(node, attribute.name, n[attribute.name])
        genome.nodes[node.key] = node
    for c in data["connections"]:
        key = tuple(c["key"])
        conn = gc.connection_gene_type(key, innovation=c["innovation"])
        for attribute in conn._gene_attributes:
            setattr(conn, attribute.name, c[attribute.name])
        genome.connections[key] = conn
    return genome


def _peek(counter) -> int | None:
    """The next value of an ``itertools.count`` (replacing it is the caller's job)."""
    return None if counter is None else next(counter)


def population_to_dict(pop: neat.Population) -> dict:
    """Everything needed to continue ``pop`` (call between generations).

    Reading the counters advances them, so they are re-created at the same values.
    """
    config = pop.config
    species_set = pop.species
    repro = pop.reproduction
    next_genome = _peek(repro.genome_indexer)
    repro.genome_indexer = count(next_genome)
    next_species = _peek(species_set.indexer)
    species_set.indexer = count(next_species)
    next_node = _peek(config.genome_config.node_indexer)
    if next_node is not None:
        config.genome_config.node_indexer = count(next_node)
    tracker = repro.innovation_tracker
    state = random.getstate()
    return {
        "generation": pop.generation,
        "random_state": [state[0], list(state[1]), state[2]],
        "genomes": [genome_to_dict(g) for g in pop.population.values()],
        "species": [
            {
                "key": s.key,
                "created": s.created,
                "last_improved": s.last_improved,
                "representative": s.representative.key,
                "members": list(s.members),
                "fitness": s.fitness,
                "adjusted_fitness": s.adjusted_fitness,
                "fitness_history": list(s.fitness_history),
            }
            for s in species_set.species.values()
        ],
        "genome_to_species": [[g, s] for g, s in species_set.genome_to_species.items()],
        "next_species_key": next_species,
        "next_genome_key": next_genome,
        "next_node_key": next_node,
        "innovation": {
            "global_counter": tracker.global_counter,
            "generation": [[list(k), v] for k, v in tracker.generation_innovations.items()],
        },
        "compatibility_threshold": config.species_set_config.compatibility_threshold,
    }


def _check_population_dict(data: dict) -> None:
    """Check the counters and species of a population dict (the genomes are checked apart)."""
    w = "population."
    require(data, "generation", int, w)
    for key in ("next_species_key", "next_genome_key"):
        require(data, key, int, w)
    require(data, "next_node_key", int, w, none_ok=True)
    require(data, "compatibility_threshold", float, w)
    require(data, "random_state", list, w)
    require(data, "genome_to_species", list, w)
    innovation = require(data, "innovation", dict, w)
    require(innovation, "global_counter", int, f"{w}innovation.")
    require(innovation, "generation", list, f"{w}innovation.")
    for i, s in enumerate(require(data, "species", list, w)):
        ws = f"{w}species[{i}]."
        for key in ("key", "created", "last_improved", "representative"):
            require(s, key, int, ws)
        for key in ("fitness", "adjusted_fitness"):
            require(s, key, float, ws, none_ok=True)
        require(s, "members", list, ws)
        require(s, "fitness_history", list, ws)
    if data["generation"] < 0:
        raise ValueError(f"{w}generation must not be negative, got {data['generation']}")


def _check_consistency(data: dict, genomes: dict) -> None:
    """What a population needs besides well-formed parts: species, members and counters.

    Every genome is in exactly one species (so there is at least one), the species map
    says so too, and each counter is past every key in use: a new genome, species or
    node must not take the key of an existing one.

    Raises:
        ValueError: naming the first entry that breaks one of these.
    """
    w = "population."
    species = data["species"]
    if genomes and not species:
        raise ValueError(f"{w}species is empty, but every genome belongs to a species")
    home: dict[int, int] = {}
    for i, s in enumerate(species):
        members = s["members"]
        if not members:
            raise ValueError(f"{w}species[{i}].members is empty")
        unknown = {s["representative"], *members} - set(genomes)
        if unknown:
            raise ValueError(f"{w}species[{i}] holds genomes not in the population")
        if len(set(members)) != len(members):
            raise ValueError(f"{w}species[{i}].members lists a genome twice")
        for g in members:
            if home.setdefault(g, s["key"]) != s["key"]:
                raise ValueError(f"{w}genome {g} is in more than one species")
        for k, f in enumerate(s["fitness_history"]):
            if isinstance(f, bool) or not isinstance(f, (int, float)) or not math.isfinite(f):
                raise ValueError(f"{w}species[{i}].fitness_history[{k}] must be a number")
    homeless = sorted(set(genomes) - set(home))
    if homeless:
        raise ValueError(f"{w}genome {homeless[0]} is in no species")
    if len({s["key"] for s in species}) != len(species):
        raise ValueError(f"{w}species keys must be unique")
    try:
        mapped = {g: s for g, s in data["genome_to_species"]}
    except (TypeError, ValueError):
        raise ValueError(f"{w}genome_to_species must list [genome, species] pairs") from None
    if mapped != home:
        raise ValueError(f"{w}genome_to_species disagrees with the species' members")
    counters = {
        "next_genome_key": max(genomes, default=None),
        "next_species_key": max(home.values(), default=None),
        "next_node_key": max((n["key"] for g in data["genomes"] for n in g["nodes"]), default=None),
    }
    for key, used in counters.items():
        value = data[key]
        if value is not None and used is not None and value <= used:
            raise ValueError(f"{w}{key} is {value}, but key {used} is already in use")


def population_from_dict(data: dict, config: neat.Config) -> neat.Population:
    """Rebuild a population written by :func:`population_to_dict` (with the same config).

    Raises:
        ValueError: ``data`` is not such a population; the message names the entry.
        KeyError, TypeError: an entry refers to a genome that is not there, or a
            counter or the random state has the wrong form.

    """
    _check_population_dict(data)
    genomes = {}
    for i, g in enumerate(require(data, "genomes", list, "population.")):
        genome = genome_from_dict(g, config, f"population.genomes[{i}].")
        if genome.key in genomes:
            raise ValueError(f"population.genomes[{i}].key {genome.key} is used twice")
        genomes[genome.key] = genome
    _check_consistency(data, genomes)
    species_set = config.species_set_type(config.species_set_config, neat.reporting.ReporterSet())
    for s in data["species"]:
        species = Species(s["key"], s["created"])
        species.last_improved = s["last_improved"]
        species.representative = genomes[s["representative"]]
        species.members = {gid: genomes[gid] for gid in s["members"]}
        species.fitness = s["fitness"]
        species.adjusted_fitness = s["adjusted_fitness"]
        species.fitness_history = list(s["fitness_history"])
        species_set.species[species.key] = species
    species_set.genome_to_species = {g: s for g, s in data["genome_to_species"]}
    species_set.indexer = count(data["next_species_key"])
    config.species_set_config.compatibility_threshold = data["compatibility_threshold"]
    pop = neat.Population(config, initial_state=(genomes, species_set, data["generation"]))
    pop.reproduction.genome_indexer = count(data["next_genome_key"])
    tracker = pop.reproduction.innovation_tracker
    tracker.global_counter = data["innovation"]["global_counter"]
    tracker.generation_innovations = {tuple(k): v for k, v in data["innovation"]["generation"]}
    config.genome_config.innovation_tracker = tracker
    nxt = data["next_node_key"]
    config.genome_config.node_indexer = None if nxt is None else count(nxt)
    try:
        version, internal, gauss = data["random_state"]
        random.setstate((version, tuple(internal), gauss))
    except (OverflowError, TypeError, ValueError) as e:  # numbers no generator holds
        raise ValueError(
            f"population.random_state is not a random generator's state ({e})"
        ) from None
    return pop
