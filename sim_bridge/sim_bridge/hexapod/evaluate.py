"""Executing hexapod primitives from rest: the legged robot's evaluation (paper Sec. V-B).

Kept so that ``sim_bridge.hexapod.evaluate`` names what it always did;
:mod:`sim_bridge.legged.evaluate` holds the code.
"""

from sim_bridge.legged.evaluate import HEADING, PATH, SECONDS, TILT, X, Y, evaluate_genes

__all__ = ["HEADING", "PATH", "SECONDS", "TILT", "X", "Y", "evaluate_genes"]
