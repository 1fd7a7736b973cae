"""A neat-python population as plain JSON data, for resume checkpoints.

neat-python's own checkpoints are pickles, and a pickle runs code when loaded, so a
checkpoint file handed over by someone else could run anything. This module writes
everything a run needs to continue exactly where it stopped (genomes with their genes in
order, species, counters, the innovation tracker, the adaptive compatibility threshold
and Python's random state) as JSON, and rebuilds the objects from it.
"""

from __future__ import annotations

import random
from itertools import count

import neat
from neat.species import Species


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


def genome_from_dict(data: dict, config: neat.Config):
    """Rebuild a genome written by :func:`genome_to_dict`."""
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


def population_from_dict(data: dict, config: neat.Config) -> neat.Population:
    """Rebuild a population written by :func:`population_to_dict` (with the same config)."""
    genomes = {}
    for g in data["genomes"]:
        genome = genome_from_dict(g, config)
        genomes[genome.key] = genome
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
    version, internal, gauss = data["random_state"]
    random.setstate((version, tuple(internal), gauss))
    return pop
