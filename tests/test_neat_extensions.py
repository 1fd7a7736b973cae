"""The two Table I knobs added to neat-python: crossover probability, target species count."""

import random

import neat
import pytest
from neat_helpers import neat_config, random_genomes

from offline_evolution.arbitrator.neat_classes import TargetSpeciesSet, exact_spawn
from offline_evolution.arbitrator.neat_config import load_neat_config


def child_of(config, p1, p2, probability, seed):
    config.genome_config.crossover_probability = probability
    random.seed(seed)
    child = config.genome_type(999)
    child.configure_crossover(p1, p2, config.genome_config)
    return child


def weights(genome):
    return {k: c.weight for k, c in genome.connections.items()}


def test_without_crossover_children_are_clones_of_the_first_parent():
    config = neat_config()
    p1, p2 = random_genomes(config, 2, mutations=0, seed=4)
    p1.fitness, p2.fitness = 1.0, 2.0  # p2 fitter: crossover would favour its genes
    for seed in range(20):
        assert weights(child_of(config, p1, p2, 0.0, seed)) == weights(p1)


def test_with_crossover_children_mix_both_parents():
    config = neat_config()
    p1, p2 = random_genomes(config, 2, mutations=0, seed=4)
    p1.fitness, p2.fitness = 1.0, 2.0
    w1, w2 = weights(p1), weights(p2)
    child = weights(child_of(config, p1, p2, 1.0, 0))
    assert any(child[k] == w1[k] for k in child) and any(child[k] == w2[k] for k in child)


def test_crossover_happens_with_the_configured_probability():
    config = neat_config()
    p1, p2 = random_genomes(config, 2, mutations=0, seed=4)
    p1.fitness, p2.fitness = 1.0, 2.0
    mixed = sum(weights(child_of(config, p1, p2, 0.2, s)) != weights(p1) for s in range(2000))
    assert mixed / 2000 == pytest.approx(0.2, abs=0.03)


def test_shipped_settings_are_table_one():
    config = neat_config()
    g, r, s = config.genome_config, config.reproduction_config, config.species_set_config
    assert config.pop_size == 150
    assert (r.survival_threshold, s.target_species_count) == (0.2, 5)
    assert (g.weight_mutate_rate, g.bias_mutate_rate, g.crossover_probability) == (0.25, 0.3, 0.2)
    assert (g.conn_add_prob, g.node_add_prob) == (0.05, 0.03)
    assert g.activation_options == ["sigmoid"] and g.feed_forward


@pytest.mark.parametrize(("species", "expected"), [(2, 2.7), (5, 3.0), (9, 3.3)])
def test_threshold_moves_towards_the_target_species_count(monkeypatch, species, expected):
    config = neat_config()
    pop = neat.Population(config, seed=1)
    sset = pop.species
    assert isinstance(sset, TargetSpeciesSet)
    config.species_set_config.compatibility_threshold = 3.0

    def fake_speciate(self, config, population, generation):
        self.species = {k: object() for k in range(species)}

    monkeypatch.setattr(neat.DefaultSpeciesSet, "speciate", fake_speciate)
    sset.speciate(config, pop.population, 1)
    assert config.species_set_config.compatibility_threshold == pytest.approx(expected)


def test_evolution_keeps_the_species_count_near_the_target():
    config = neat_config()
    pop = neat.Population(config, seed=2)
    counts = []

    def fitness(genomes, config):
        for _, g in genomes:
            g.fitness = sum(c.weight for c in g.connections.values())

    for _ in range(40):
        pop.run(fitness, 1)
        counts.append(len(pop.species.species))
    assert 3 <= sum(counts[-15:]) / 15 <= 8


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_population_of_16_evolves_to_the_end(seed):
    """neat-python stopped such runs with a RuntimeError (too many species for 16 genomes,
    or spawn counts its single pass could not fix); species are now capped and merged."""
    config = load_neat_config("config/neat/4ws.ini", 10, 2)
    config.pop_size = 16
    pop = neat.Population(config, seed=seed)
    rng = random.Random(seed)

    def fitness(genomes, config):  # noisy, so species keep appearing and stagnating
        for _, g in genomes:
            g.fitness = sum(c.weight for c in g.connections.values()) + rng.random()

    cap = 16 // max(config.reproduction_config.min_species_size, config.reproduction_config.elitism)
    for _ in range(300):
        pop.run(fitness, 1)
        assert len(pop.species.species) <= cap
        assert len(pop.population) == 16


@pytest.mark.parametrize(
    ("spawn", "pop", "minimum", "expected"),
    [
        ([9, 9, 2, 2], 16, 2, [6, 6, 2, 2]),  # 6 too many: more than one pass over species
        ([1, 1, 1], 9, 2, [3, 3, 3]),  # below the minimum, then short
        ([4, 4], 8, 2, [4, 4]),
    ],
)
def test_exact_spawn_meets_the_population_size_and_the_minimum(spawn, pop, minimum, expected):
    out = exact_spawn(spawn, pop, minimum)
    assert out == expected and sum(out) == pop and min(out) >= minimum
