"""Mazes for training and held-out evaluation (docs/design.md section 21).

The clearance-aware path search (:mod:`~offline_evolution.mazes.paths`), the seeded maze
generator (:mod:`~offline_evolution.mazes.generator`) and maze files written back
(:mod:`~offline_evolution.mazes.files`).
"""
