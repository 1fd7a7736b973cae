"""Mazes for the navigation task (paper Sec. IV-B, docs/design.md section 4).

A maze file is YAML in ``config/mazes/``::

    name: obstacle
    description: free text
    wall_thickness: 0.01          # m
    walls:                        # wall centre lines [x1, y1, x2, y2], m, maze frame
      - [-5.5658, 0.7528, 5.5404, 0.7528]
    start:
      pose: [-5.456, 0.654, 0]    # nominal start [x m, y m, heading deg], used by replays
      region:                     # random starts: uniform in this box, heading in range
        x: [-5.50, -5.30]
        y: [0.30, 0.70]
        heading_deg: [-180, 180]
    target: [5.338, 0.120]        # m
    target_radius: 0.15           # m, reached when the robot's centre is this close

The maze frame is x to the right (towards the target), y up; robots live in it with
REP 103 conventions. Each wall is a box of the segment's length and the wall thickness
(see :mod:`sim_bridge.geometry`).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from evorbc_ros.config import ConfigError, config_dir, load_yaml_mapping
from evorbc_ros.limits import MAZE_WALLS
from sim_bridge.geometry import WallGrid, box_corners, box_distances, clearance, wall_boxes

_KEYS = {"name", "description", "wall_thickness", "walls", "start", "target", "target_radius"}


@dataclass(frozen=True, eq=False)
class Maze:
    """A maze: walls, where robots start, and the target (compared by identity)."""

    name: str
    walls: np.ndarray  # (m, 4) wall centre lines (x1, y1, x2, y2), m
    wall_thickness: float  # m
    start_pose: tuple[float, float, float]  # x m, y m, heading rad
    start_x: tuple[float, float]  # m, start region
    start_y: tuple[float, float]  # m
    start_heading: tuple[float, float]  # rad
    target: tuple[float, float]  # m
    target_radius: float  # m
    description: str = ""

    @cached_property
    def boxes(self) -> np.ndarray:
        """``(m, 6)`` wall boxes for the compiled geometry."""
        return wall_boxes(self.walls, self.wall_thickness)

    @cached_property
    def _all_walls(self) -> np.ndarray:
        return np.arange(len(self.walls), dtype=np.int64)

    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the walls' outer surfaces, m."""
        corners = box_corners(self.boxes).reshape(-1, 2)
        lo, hi = corners.min(axis=0), corners.max(axis=0)
        return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])

    def size(self) -> tuple[float, float]:
        """Width and height of the maze, m."""
        x0, y0, x1, y1 = self.bounds()
        return x1 - x0, y1 - y0

    def clearance(self, x: float, y: float) -> float:
        """Distance (m) from ``(x, y)`` to the nearest wall surface."""
        return float(clearance(x, y, self.boxes, self._all_walls))

    def start_misfit(self, robot_radius: float, robot: str = "the robot") -> str | None:
        """Why a robot of footprint radius ``robot_radius`` (m) cannot start here, or None.

        The nominal start pose must clear the footprint, as random starts do: a start
        inside a wall would begin an episode in contact (the 4WS model cannot leave it).
        """
        x, y, _ = self.start_pose
        room = self.clearance(x, y)
        if room >= robot_radius:
            return None
        return (
            f"robot {robot} does not fit maze {self.name}: at the maze's start "
            f"({x:.2f}, {y:.2f}) m the nearest wall is {room:.3f} m away, and the robot "
            f"needs {robot_radius:.3f} m"
        )

    def clearances(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`clearance` for arrays of points (m)."""
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        return np.min([box_distances(x, y, b) for b in self.boxes], axis=0)

    def wall_grid(self, reach: float, cell: float = 0.2) -> WallGrid:
        """Broad-phase index for queries reaching ``reach`` m (see :class:`WallGrid`)."""
        return WallGrid.build(self.boxes, reach, cell)

    def sample_starts(
        self, rng: np.random.Generator, n: int, robot_radius: float, max_tries: int = 10000
    ) -> np.ndarray:
        """``(n, 3)`` random start poses ``(x, y, heading)`` whose footprint is clear.

        Positions are uniform in the start region and headings uniform in its range;
        positions where a footprint of ``robot_radius`` would touch a wall are redrawn.
        """
        poses = np.empty((n, 3))
        for k in range(n):
            for _ in range(max_tries):
                x = rng.uniform(*self.start_x)
                y = rng.uniform(*self.start_y)
                if self.clearance(x, y) >= robot_radius:
                    break
            else:
                raise ValueError(
                    f"maze {self.name}: no start in the start region clears a "
                    f"robot of radius {robot_radius} m"
                )
            poses[k] = (x, y, rng.uniform(*self.start_heading))
        return poses

    def to_dict(self) -> dict:
        """Plain-data form (the YAML layout, headings in degrees)."""
        return {
            "name": self.name,
            "description": self.description,
            "wall_thickness": self.wall_thickness,
            "walls": self.walls.tolist(),
            "start": {
                "pose": [self.start_pose[0], self.start_pose[1], math.degrees(self.start_pose[2])],
                "region": {
                    "x": list(self.start_x),
                    "y": list(self.start_y),
                    "heading_deg": [math.degrees(h) for h in self.start_heading],
                },
            },
            "target": list(self.target),
            "target_radius": self.target_radius,
        }


#: How far from the origin a wall may reach (m): a maze a kilometre across, where the
#: shipped ones are 11 m.
MAX_COORDINATE = 500.0


def _numbers(value, count: int, where: str, source: str) -> tuple[float, ...]:
    if (
        not isinstance(value, (list, tuple))
        or len(value) != count
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    ):
        raise ConfigError(f"{source}: {where} must be a list of {count} numbers, got {value!r}")
    out = tuple(float(v) for v in value)
    if not all(math.isfinite(v) for v in out):
        raise ConfigError(f"{source}: {where} must be finite, got {value!r}")
    return out


def _interval(value, where: str, source: str) -> tuple[float, float]:
    lo, hi = _numbers(value, 2, where, source)
    if lo > hi:
        raise ConfigError(f"{source}: {where} must be [low, high] with low <= high")
    return lo, hi


def maze_from_dict(data: dict, source: str) -> Maze:
    """Build and validate a maze from its YAML mapping.

    Raises:
        ConfigError: naming ``source`` and the offending key.
    """
    unknown = set(data) - _KEYS
    if unknown:
        raise ConfigError(
            f"{source}: unknown key {sorted(unknown)[0]!r}; known keys: {', '.join(sorted(_KEYS))}"
        )
    for key in ("name", "walls", "start", "target"):
        if key not in data:
            raise ConfigError(f"{source}: missing key {key!r}")
    if not isinstance(data["name"], str) or not data["name"]:
        raise ConfigError(f"{source}: name must be a non-empty string")
    thickness = data.get("wall_thickness", 0.01)
    if (
        isinstance(thickness, bool)
        or not isinstance(thickness, (int, float))
        or not (0 < thickness < 1)
    ):
        raise ConfigError(f"{source}: wall_thickness must be a number in (0, 1) m")
    walls = data["walls"]
    if not isinstance(walls, list) or not walls:
        raise ConfigError(f"{source}: walls must be a non-empty list of [x1, y1, x2, y2]")
    # From the count, before any geometry: checking and simulating cost time in the walls.
    MAZE_WALLS.check(len(walls), source, ConfigError, "in walls")
    segments = np.array([_numbers(w, 4, f"walls[{k}]", source) for k, w in enumerate(walls)])
    # The simulated sensors' lookup tables grow with the maze's size: a wall ending at
    # 1e30 m asked numpy for more than it can index, one at 5e6 m for 3 GiB.
    far = np.abs(segments).max(axis=1)
    if far.max() > MAX_COORDINATE:
        k = int(np.argmax(far))
        raise ConfigError(
            f"{source}: walls[{k}] reaches {far[k]:.3g} m from the origin; a maze lies within "
            f"{MAX_COORDINATE:g} m of it"
        )
    lengths = np.hypot(segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1])
    if np.any(lengths <= 0):
        k = int(np.argmin(lengths))
        raise ConfigError(f"{source}: walls[{k}] has zero length")
    start = data["start"]
    if not isinstance(start, dict) or "pose" not in start or "region" not in start:
        raise ConfigError(f"{source}: start must have 'pose' and 'region'")
    _only(start, {"pose", "region"}, "start", source)
    pose = _numbers(start["pose"], 3, "start.pose", source)
    region = start["region"]
    if not isinstance(region, dict) or not {"x", "y"} <= set(region):
        raise ConfigError(f"{source}: start.region must have 'x' and 'y' intervals")
    _only(region, {"x", "y", "heading_deg"}, "start.region", source)
    heading = _interval(region.get("heading_deg", [-180, 180]), "start.region.heading_deg", source)
    radius = data.get("target_radius", 0.15)
    if isinstance(radius, bool) or not isinstance(radius, (int, float)) or radius <= 0:
        raise ConfigError(f"{source}: target_radius must be a positive number (m)")
    description = data.get("description", "")
    if not isinstance(description, str):
        raise ConfigError(f"{source}: description must be text")
    maze = Maze(
        name=data["name"],
        walls=segments,
        wall_thickness=float(thickness),
        start_pose=(pose[0], pose[1], math.radians(pose[2])),
        start_x=_interval(region["x"], "start.region.x", source),
        start_y=_interval(region["y"], "start.region.y", source),
        start_heading=(math.radians(heading[0]), math.radians(heading[1])),
        target=_numbers(data["target"], 2, "target", source),
        target_radius=float(radius),
        description=description,
    )
    x0, y0, x1, y1 = maze.bounds()
    for where, (x, y) in (("start.pose", pose[:2]), ("target", maze.target)):
        if not (x0 < x < x1 and y0 < y < y1):
            raise ConfigError(f"{source}: {where} ({x}, {y}) lies outside the maze")
        if maze.clearance(x, y) <= 0:
            raise ConfigError(f"{source}: {where} ({x}, {y}) lies inside a wall")
    if not (
        x0 < maze.start_x[0]
        and maze.start_x[1] < x1
        and y0 < maze.start_y[0]
        and maze.start_y[1] < y1
    ):
        raise ConfigError(
            f"{source}: start.region must lie inside the maze "
            f"(x {x0:.3f}..{x1:.3f}, y {y0:.3f}..{y1:.3f})"
        )
    return maze


def _only(mapping: dict, keys: set[str], where: str, source: str) -> None:
    unknown = set(mapping) - keys
    if unknown:
        raise ConfigError(
            f"{source}: unknown key {where}.{sorted(unknown)[0]}; known: {', '.join(sorted(keys))}"
        )


def load_maze(path: str | os.PathLike) -> Maze:
    """Load and validate a maze file (see the module docstring for the layout)."""
    return maze_from_dict(load_yaml_mapping(path, {"walls": MAZE_WALLS}), str(path))


def maze_dir() -> Path:
    """Folder of the shipped mazes."""
    return config_dir() / "mazes"


def maze_names() -> list[str]:
    """Names of the shipped mazes, sorted."""
    return sorted(p.stem for p in maze_dir().glob("*.yaml"))


def is_maze_file(name_or_path: str) -> bool:
    """True if ``name_or_path`` names a maze file (a path), False if a shipped maze's name."""
    return name_or_path.endswith((".yaml", ".yml")) or os.sep in name_or_path


def load_named_maze(name_or_path: str) -> Maze:
    """A shipped maze by name, or any maze file by path."""
    if is_maze_file(name_or_path):
        return load_maze(name_or_path)
    # A name is looked up among the shipped ones, never joined into a path: a 300-letter
    # name would otherwise fail in the file system (ENAMETOOLONG), not as an unknown maze.
    names = maze_names()
    if name_or_path not in names:
        raise ConfigError(f"unknown maze {name_or_path!r}; shipped mazes: {', '.join(names)}")
    return load_maze(maze_dir() / f"{name_or_path}.yaml")
