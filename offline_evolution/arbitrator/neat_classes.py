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
        c = self.species_set_config
        n = len(self.species)
        if n < c.target_species_count:
            c.compatibility_threshold = max(
                c.threshold_min, c.compatibility_threshold - c.threshold_step
            )
        elif n > c.target_species_count:
            c.compatibility_threshold += c.threshold_step
