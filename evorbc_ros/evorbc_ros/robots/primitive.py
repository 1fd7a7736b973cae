"""What every robot's locomotion primitive has in common: named, ranged parameters.

A primitive is a vector of genes in [-1, 1]; gene ``k`` maps linearly onto the physical
range of parameter ``k`` (docs/design.md section 2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Genes of every primitive live in this interval (paper Table I, "gene range").
GENE_LOW, GENE_HIGH = -1.0, 1.0


@dataclass(frozen=True)
class ParameterSpec:
    """One locomotion parameter: its name, SI unit and physical range."""

    name: str
    unit: str
    low: float
    high: float

    def to_physical(self, gene: np.ndarray | float) -> np.ndarray:
        """Map genes in [-1, 1] linearly onto ``[low, high]``."""
        g = np.asarray(gene, dtype=np.float64)
        return self.low + (g - GENE_LOW) * (self.high - self.low) / (GENE_HIGH - GENE_LOW)

    def to_gene(self, value: np.ndarray | float) -> np.ndarray:
        """Inverse of :meth:`to_physical`."""
        v = np.asarray(value, dtype=np.float64)
        return GENE_LOW + (v - self.low) * (GENE_HIGH - GENE_LOW) / (self.high - self.low)

    def as_dict(self) -> dict:
        """Plain-data form used in repertoire files."""
        return {"name": self.name, "unit": self.unit, "low": self.low, "high": self.high}
