"""Mazes that fit the robot: moved to :mod:`sim_bridge.maze_fit` (docs/design.md section 21).

The simulation bridge fits a maze as offline runs do, and it may not import this package
(docs/design.md section 19), so the fitting lives in the layer below. This name stays for
code that imports it from here.
"""

from sim_bridge.maze_fit import (
    MARGIN_RATIO,
    fit_scale,
    fitted_maze,
    misfit_reason,
    scaled_maze,
)

__all__ = ["MARGIN_RATIO", "fit_scale", "fitted_maze", "misfit_reason", "scaled_maze"]
