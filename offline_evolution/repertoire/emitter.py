"""The paper's variation: uniform random solutions, then per-gene Gaussian mutants.

Paper Algorithm 1 and Table I: the first batch holds ``initial_batch`` solutions drawn
uniformly from the gene range; every later batch holds ``batch_size`` mutants, each of an
elite chosen uniformly at random, whose genes each mutate with probability
``mutation_probability`` by N(0, ``sigma``) and are clipped to [-1, 1].

The initial batch is handed out in pieces of at most ``batch_size`` so that slow robots
report progress and checkpoint during it. The pieces are the same draws from the same
generator as one big batch, and adding them to the archive one after another keeps the
same elites (a cell only takes a strictly better solution).

Parents are drawn from the elites ordered by cell, with the emitter's own generator, so a
run restored from a checkpoint (whose archive was refilled in a different order) draws
exactly the same parents as an uninterrupted one.

:class:`IsoLineDDEmitter` replaces the mutation by Iso+LineDD (Vassiliades & Mouret 2018):
a child is ``x_i + N(0, iso_sigma^2 I) + N(0, line_sigma^2) (x_j - x_i)`` for two elites
``x_i, x_j``, so it moves along the direction that joins elites ("directional variation")
and explores the elite hypervolume rather than the whole gene cube.
"""

from __future__ import annotations

import numpy as np
from ribs.emitters import EmitterBase
from ribs.emitters.operators import IsoLineOperator

from evorbc_ros.robots.primitive import GENE_HIGH, GENE_LOW
from offline_evolution.repertoire.archive import elites_by_cell


class PaperMutationEmitter(EmitterBase):
    """pyribs emitter implementing the paper's random initialisation and mutation."""

    def __init__(
        self,
        archive,
        *,
        initial_batch: int,
        batch_size: int,
        mutation_probability: float,
        sigma: float,
        seed: int,
    ) -> None:
        super().__init__(
            archive,
            solution_dim=archive.solution_dim,
            bounds=None,
            lower_bounds=None,
            upper_bounds=None,
        )
        self.initial_batch = initial_batch
        self.batch_size = batch_size
        self.mutation_probability = mutation_probability
        self.sigma = sigma
        self.rng = np.random.default_rng(seed)
        self.initial_remaining = initial_batch  # random solutions still to hand out

    def ask(self) -> np.ndarray:
        """The next batch of genes, ``(n, solution_dim)`` in [-1, 1]."""
        d = self.solution_dim
        if self.initial_remaining > 0 or self.archive.empty:
            # An empty archive after the initial batch (e.g. every legged primitive fell
            # over) gets more random solutions rather than mutants of nothing.
            n = min(self.batch_size, self.initial_remaining) or self.batch_size
            self.initial_remaining = max(0, self.initial_remaining - n)
            return self.rng.uniform(GENE_LOW, GENE_HIGH, size=(n, d))
        return self.vary(elites_by_cell(self.archive)["solution"])

    def vary(self, elites: np.ndarray) -> np.ndarray:
        """``batch_size`` children of uniformly chosen ``elites`` (the paper's mutation)."""
        d = self.solution_dim
        chosen = elites[self.rng.integers(len(elites), size=self.batch_size)]
        mutate = self.rng.random((self.batch_size, d)) < self.mutation_probability
        noise = self.rng.normal(0.0, self.sigma, size=(self.batch_size, d))
        return np.clip(chosen + np.where(mutate, noise, 0.0), GENE_LOW, GENE_HIGH)

    def get_state(self) -> dict:
        """Plain-data state for checkpoints (JSON-safe)."""
        return {"rng": self.rng.bit_generator.state, "initial_remaining": self.initial_remaining}

    def set_state(self, state: dict) -> None:
        """Restore what :meth:`get_state` returned."""
        try:
            self.rng.bit_generator.state = state["rng"]
        except (OverflowError, TypeError, ValueError) as e:  # numbers no generator holds
            raise ValueError(f"emitter.rng is not a random generator's state ({e})") from None
        self.initial_remaining = int(state["initial_remaining"])


class IsoLineDDEmitter(PaperMutationEmitter):
    """The paper's random first batch, then Iso+LineDD children of pairs of elites."""

    def __init__(self, archive, *, iso_sigma: float, line_sigma: float, **kwargs) -> None:
        super().__init__(archive, mutation_probability=0.0, sigma=0.0, **kwargs)
        self.iso_sigma = iso_sigma
        self.line_sigma = line_sigma

    def vary(self, elites: np.ndarray) -> np.ndarray:
        """``batch_size`` Iso+LineDD children, clipped to the gene range."""
        pairs = elites[self.rng.integers(len(elites), size=(2, self.batch_size))]
        # pyribs' operator keeps its own generator; seeding it from ours each batch keeps
        # the whole run reproducible from the emitter state alone (checkpoints).
        operator = IsoLineOperator(
            self.iso_sigma, self.line_sigma, seed=int(self.rng.integers(2**63))
        )
        return np.clip(operator.ask(pairs), GENE_LOW, GENE_HIGH)
