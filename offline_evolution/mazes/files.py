"""Maze files written back: a generated maze as an ordinary ``config/mazes`` file."""

from __future__ import annotations

import os

import yaml

from evorbc_ros.atomic_io import atomic_write_text
from sim_bridge.maze import Maze


def _tidy(value):
    """Numbers rounded to 1e-9 (so 60 deg is written as 60, docs/design.md section 1)."""
    if isinstance(value, float):
        rounded = round(value, 9)
        return int(rounded) if rounded.is_integer() and abs(rounded) < 1e15 else rounded
    if isinstance(value, list):
        return [_tidy(v) for v in value]
    if isinstance(value, dict):
        return {k: _tidy(v) for k, v in value.items()}
    return value


def maze_text(maze: Maze, header: str = "") -> str:
    """The YAML text of ``maze`` (the layout :func:`sim_bridge.maze.load_maze` reads).

    ``header`` becomes comment lines at the top (units, where the maze came from).
    """
    comment = "".join(f"# {line}\n" for line in header.splitlines())
    body = yaml.safe_dump(_tidy(maze.to_dict()), sort_keys=False, default_flow_style=None)
    return comment + body


def save_maze(maze: Maze, path: str | os.PathLike, header: str = "") -> None:
    """Write ``maze`` to ``path`` as a maze file, atomically."""
    atomic_write_text(path, maze_text(maze, header))
