"""What a robot's mazes ask of its gait design: speed, episode time, walls (docs/legged.md).

The design search scores a design against the mazes the generator sizes for the robot
(:func:`offline_evolution.mazes.generator.sized_spec`, docs/design.md section 21): its
own maze fitted to its footprint, and the generated mazes whose longest path from any
start is ``path_limit``. From that spec:

* **required speed** (m/s) ``= path_limit / (2/3 x episode_time)``: the generator keeps a
  maze's longest path within 2/3 of what the robot drives at its top speed in an episode
  (the rest is for turns and detours), so a robot whose top speed is below this cannot
  cross its own generated mazes in time. The A1: 8.67 m / 20 s = 0.43 m/s.
* **the room** (m): every other switching episode runs in a square room as wide inside as
  the maze's narrowest gap, built of the maze's walls (same thickness, same height, same
  PyBullet boxes as a maze episode's, :class:`sim_bridge.legged.physics.LeggedSim`), its
  forward gaits pressing against a wall as they do in a maze's narrow passages
  (sim_bridge/legged/gait_measures.py).

The robot's maze and episode time are its registration's when its settings name a
registered robot, otherwise those ``robot-from-urdf`` declares for every robot it makes
(:data:`DEFAULT_MAZE`, :data:`DEFAULT_EPISODE_TIME`).

A design slower than its mazes ask gets a longer episode instead of mazes it cannot
cross in time (:func:`fitted_episode_time`): its maze keeps its size and layout, the
episode grows to what its speed needs, as the slow 4WS robot's 120 s episodes do for its
0.2 m/s (docs/your-robot.md, "Episode time from the design").
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from sim_bridge.geometry import wall_boxes
from sim_bridge.legged.settings import LeggedRobotSettings

#: The maze and episode time (s) of a robot ``robot-from-urdf`` declares
#: (sim_bridge/legged/urdf_settings.py, ``declaration_text``).
DEFAULT_MAZE = "a1"
DEFAULT_EPISODE_TIME = 30.0
#: Share of an episode the generator allows for the longest path at top speed.
PATH_SHARE = 2.0 / 3.0
#: s: a fitted episode time is a whole number of these (30, 70, 90 s ...).
EPISODE_STEP = 5.0
#: s: the longest fitted episode, the 4WS robots' (a slower gait is not made to fit).
MAX_FITTED_EPISODE = 120.0


@dataclass(frozen=True)
class MazeNeeds:
    """The maze side of the design objective (lengths m, times s, speeds m/s)."""

    maze: str  # the robot's own maze
    episode_time: float  # s, a maze episode
    path: float  # m, the longest path of a generated maze (MazeSpec.path_limit)
    room: float  # m, inner side of the switching room (the maze's narrowest gap)
    wall_thickness: float  # m

    @property
    def required_speed(self) -> float:
        """m/s the robot's fastest gaits must make (module docstring)."""
        return self.path / (PATH_SHARE * self.episode_time)

    def room_boxes(self) -> np.ndarray:
        """``(4, 6)`` wall boxes of the room, centred on the origin (maze frame)."""
        h = 0.5 * (self.room + self.wall_thickness)  # m, to the walls' centre lines
        corners = [(-h, -h), (h, -h), (h, h), (-h, h)]
        segments = [(*corners[k], *corners[(k + 1) % 4]) for k in range(4)]
        return wall_boxes(np.array(segments), self.wall_thickness)

    def as_dict(self) -> dict:
        """Plain data (the checkpoint and the settings file's record)."""
        return {**asdict(self), "required_speed": self.required_speed}


def robot_maze(name: str) -> tuple[str, float]:
    """The maze and episode time (s) of the robot called ``name``.

    Its registration's if it is registered, otherwise :data:`DEFAULT_MAZE` and
    :data:`DEFAULT_EPISODE_TIME`.
    """
    from evorbc_ros.robots import registry

    if registry.known(name):
        robot = registry.lookup(name)
        return robot.maze, robot.episode_time
    return DEFAULT_MAZE, DEFAULT_EPISODE_TIME


def maze_needs(settings: LeggedRobotSettings) -> MazeNeeds:
    """What the mazes of the robot of ``settings`` ask of its gait.

    Raises:
        ConfigError: its maze cannot be sized for its footprint (one line).
    """
    from offline_evolution.mazes.generator import sized_spec

    maze, episode_time = robot_maze(settings.name)
    spec = sized_spec(
        settings.name, maze, settings.footprint_radius, settings.speed_bound, episode_time
    )
    return MazeNeeds(
        maze=maze,
        episode_time=episode_time,
        path=round(spec.path_limit, 4),
        room=round(spec.narrow_gap[0], 4),
        wall_thickness=spec.wall_thickness,
    )


def fitted_episode_time(record: dict | None) -> tuple[float, str]:
    """The episode time (s) of a robot whose gait design search left ``record``.

    ``record`` is a designed settings file's ``design_search`` mapping (its ``maze`` and
    ``measures``); None (no search): :data:`DEFAULT_EPISODE_TIME`. A design whose estimated
    top speed, ``SPREAD`` x the 90th percentile of its random gaits' speed (the design
    objective's own estimate, objective.py), covers the maze's longest path within
    :data:`PATH_SHARE` of the searched episode keeps that episode; a slower one gets the
    time that speed needs, rounded up to :data:`EPISODE_STEP`, at most
    :data:`MAX_FITTED_EPISODE` (a gait slower than that is too slow for its mazes, and
    the note says so).

    Returns:
        ``(seconds, why)``: ``why`` says how it was found (a settings-file comment).
    """
    from offline_evolution.gait_design.objective import SPREAD

    if not record:
        return DEFAULT_EPISODE_TIME, "the A1's"
    maze, measures = record.get("maze") or {}, record.get("measures") or {}
    searched = float(maze.get("episode_time", DEFAULT_EPISODE_TIME))
    path, speed = float(maze.get("path", 0.0)), SPREAD * float(measures.get("speed", 0.0))
    if path <= 0.0 or speed <= 0.0:
        return searched, "the design search's"
    needed = path / (PATH_SHARE * speed)
    if needed <= searched:
        return searched, f"the design search's: its gait's {speed:.2f} m/s covers its mazes"
    seconds = EPISODE_STEP * math.ceil(needed / EPISODE_STEP - 1e-9)
    if seconds > MAX_FITTED_EPISODE:
        return MAX_FITTED_EPISODE, (
            f"at most {MAX_FITTED_EPISODE:g} s: its gait's {speed:.2f} m/s would need "
            f"{seconds:g} s for {path:.2f} m of maze path; too slow for its mazes"
        )
    return seconds, (
        f"{path:.2f} m of maze path at {speed:.2f} m/s ({SPREAD:g} x its random gaits' "
        f"p90) in {PATH_SHARE:.2f} of the episode; the design search's {searched:g} s asked "
        f"{path / (PATH_SHARE * searched):.2f} m/s"
    )
