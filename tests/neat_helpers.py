"""Random neat-python genomes for tests (hidden nodes, every activation and aggregation)."""

import random

from neat.innovation import InnovationTracker

from evorbc_ros.network import ACTIVATIONS, AGGREGATIONS
from offline_evolution.arbitrator.evolve import network_spec
from offline_evolution.arbitrator.neat_config import load_neat_config


def neat_config(n_inputs=10, n_outputs=2, all_functions=False, path="config/neat/4ws.ini"):
    config = load_neat_config(path, n_inputs, n_outputs)
    config.genome_config.innovation_tracker = InnovationTracker()
    if all_functions:
        g = config.genome_config
        g.activation_options = list(ACTIVATIONS)
        g.aggregation_options = list(AGGREGATIONS)
        g.activation_mutate_rate = 0.5
        g.aggregation_mutate_rate = 0.5
        g.response_mutate_rate = 0.5
        g.response_mutate_power = 0.5
        g.response_max_value = 3.0
        g.response_min_value = -3.0
    return config


def random_genomes(config, n, mutations=12, seed=0):
    """Genomes grown by many structural mutations, so most have hidden nodes."""
    random.seed(seed)
    g = config.genome_config
    g.node_add_prob, g.conn_add_prob, g.enabled_mutate_rate = 0.6, 0.6, 0.1
    genomes = []
    for key in range(n):
        genome = config.genome_type(key)
        genome.configure_new(g)
        for _ in range(mutations):
            genome.mutate(g)
        genomes.append(genome)
    return genomes


__all__ = ["neat_config", "network_spec", "random_genomes"]
