"""neat-python classes that add the two Table I knobs neat-python lacks.

Both plug into neat-python through its config (the section names of ``config/neat/*.ini``)
instead of forking it:

* :class:`EvoRBCGenome`: ``crossover_probability``. neat-python makes every offspring by
  crossover of two parents (identical parents give a clone). Here an offspring is a
  crossover with that probability and otherwise a clone of its first parent; the child is
  mutated either way.
* :class:`TargetSpeciesSet`: ``target_species_count``. After each speciation the
  compatibility threshold moves by ``threshold_step`` towards the target number of species
  (down when there are too few, up when too many), never below ``threshold_min``.

Two more keep small populations running where neat-python would stop mid-run with a
RuntimeError (docs/design.md section 8):

* :class:`TargetSpeciesSet` never keeps more species than the population can give each its
  minimum size (``pop_size // max(min_species_size, elitism)``): beyond that, the smallest
  species joins the species whose representative is nearest. Table I's population (150,
  5 species targeted) never reaches the cap, so the paper's runs are unchanged.
* :class:`EvoRBCReproduction` (configured by the ``[DefaultReproduction]`` section) falls
  back to a complete adjustment when neat-python's single pass cannot bring the spawn
  counts to the population size; when neat-python's pass succeeds its result is kept.
"""

from __future__ import annotations

import random

import neat
from neat.config import ConfigParameter, DefaultClassConfig


class EvoRBCGenome(neat.DefaultGenome):
    """A DefaultGenome with a crossover probability (Table I: 20 %)."""

    @classmethod
    def parse_config(cls, param_dict):
        """Read ``crossover_probability`` and pass the rest to DefaultGenome."""
        params = dict(param_dict)
        text = params.pop("crossover_probability", "1.0")
        try:
            probability = float(text)
        except ValueError:
            raise ValueError(f"crossover_probability must be a number, got {text!r}") from None
        if not 0.0 <= probability <= 1.0:
            raise ValueError(f"crossover_probability must be in [0, 1], got {probability}")
        config = super().parse_config(params)
        config.crossover_probability = probability
        return config

    @classmethod
    def write_config(cls, f, config):
        """Write DefaultGenome's settings plus ``crossover_probability``."""
        super().write_config(f, config)
        f.write(f"crossover_probability = {config.crossover_probability}\n")

    def configure_crossover(self, genome1, genome2, config):
        """Crossover with ``crossover_probability``, otherwise a clone of ``genome1``."""
        if random.random() < config.crossover_probability:
            super().configure_crossover(genome1, genome2, config)
        else:
            super().configure_crossover(genome1, genome1, config)


class TargetSpeciesSet(neat.DefaultSpeciesSet):
    """A DefaultSpeciesSet that steers the number of species (Table I: 5)."""

    @classmethod
    def parse_config(cls, param_dict):
        """Read the threshold and the target-count settings."""
        return DefaultClassConfig(
            param_dict,
            [
                ConfigParameter("compatibility_threshold", float),
                ConfigParameter("target_species_count", int),
                ConfigParameter("threshold_step", float, 0.3),
                ConfigParameter("threshold_min", float, 0.3),
            ],
            "TargetSpeciesSet",
        )

    def speciate(self, config, population, generation):
        """Speciate as neat-python does, then adjust the threshold for the next time."""
        super().speciate(config, population, generation)
        rep = config.reproduction_config
        cap = max(1, config.pop_size // max(rep.min_species_size, rep.elitism, 1))
        while len(self.species) > cap:
            self._merge_smallest(config)
        c = self.species_set_config
        n = len(self.species)
        if n < c.target_species_count:
            c.compatibility_threshold = max(
                c.threshold_min, c.compatibility_threshold - c.threshold_step
            )
        elif n > c.target_species_count:
            c.compatibility_threshold += c.threshold_step

    def _merge_smallest(self, config) -> None:
        """Move the smallest species' members into the species nearest to it.

        Smallest by member count, the newest (highest key) on ties; nearest by the genomic
        distance between representatives, the oldest on ties. Deterministic, so resumed
        runs repeat it.
        """
        small = min(self.species.values(), key=lambda s: (len(s.members), -s.key))
        others = [s for s in self.species.values() if s is not small]
        into = min(
            others,
            key=lambda s: (
                small.representative.distance(s.representative, config.genome_config),
                s.key,
            ),
        )
        into.members.update(small.members)
        for gid in small.members:
            self.genome_to_species[gid] = into.key
        del self.species[small.key]


class EvoRBCReproduction(neat.DefaultReproduction):
    """neat-python's reproduction, with a spawn adjustment that cannot fail when it may not.

    neat-python brings the species' spawn counts to ``pop_size`` in one pass over the
    species and raises when one pass is not enough, although more passes would be.
    """

    def _adjust_spawn_exact(self, spawn_amounts, pop_size, min_species_size):
        try:
            return super()._adjust_spawn_exact(list(spawn_amounts), pop_size, min_species_size)
        except RuntimeError:
            return exact_spawn(spawn_amounts, pop_size, min_species_size)


def exact_spawn(spawn: list[int], pop_size: int, min_size: int) -> list[int]:
    """Spawn counts summing to ``pop_size`` with every species at least ``min_size``.

    Args:
        spawn: (n_species,) proposed counts.
        pop_size: the population size; must be at least ``n_species * min_size``.
        min_size: the smallest count a species may get.

    Returns:
        (n_species,) counts: surplus taken from the largest species first, shortfall given
        to the smallest first (neat-python's preference), one genome at a time.
    """
    out = [max(int(v), min_size) for v in spawn]
    if len(out) * min_size > pop_size:
        raise ValueError(f"{len(out)} species of at least {min_size} do not fit in {pop_size}")
    while sum(out) > pop_size:
        i = max(range(len(out)), key=lambda k: (out[k], -k))
        out[i] -= 1
    while sum(out) < pop_size:
        i = min(range(len(out)), key=lambda k: (out[k], k))
        out[i] += 1
    return out
