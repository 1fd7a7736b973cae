"""The maze task for any legged robot from a URDF plus a settings file (parent side).

The hexapod's task (:class:`~offline_evolution.maze_task.hexapod_task.HexapodMazeTask`:
settings, mazes, starts, eq. 5 fitness, episodes spread over spawned PyBullet workers) with
the legged robot's episode (:mod:`sim_bridge.legged.episode`) for the robot its settings
file describes (``config/robots/*.yaml``, docs/legged.md). Episodes are independent and
start from a restored rest state, so results do not depend on the number of workers.
"""

from __future__ import annotations

from evorbc_ros.config import ConfigError
from evorbc_ros.robots.primitive import ParameterSpec
from offline_evolution.maze_task.base import MazeTaskBase, MazeTaskSettings
from offline_evolution.maze_task.hexapod_task import HexapodMazeTask, _run
from sim_bridge.legged.episode import EpisodeRunner, LeggedController, LeggedWorld
from sim_bridge.legged.pool import available_cores, ignore_sigint
from sim_bridge.legged.scanner import Scanner
from sim_bridge.legged.settings import LeggedRobotSettings, load_robot_settings

_runner: EpisodeRunner | None = None


def _init_worker(world: LeggedWorld) -> None:
    global _runner
    ignore_sigint()
    _runner = EpisodeRunner(world)


def _episode(job) -> dict:
    return _run(_runner, job)


class LeggedMazeTask(HexapodMazeTask):
    """The maze task of the legged robot ``robot`` describes (its ``settings`` file).

    Args:
        settings: the maze task's settings (mazes, episode time, samples, sensors).
        robot: the legged robot, or the path of its settings file.
        workers: PyBullet worker processes (default: every core).

    """

    def __init__(
        self,
        settings: MazeTaskSettings,
        robot: LeggedRobotSettings | str,
        workers: int | None = None,
    ):
        if not isinstance(robot, LeggedRobotSettings):
            robot = load_robot_settings(robot)
        self.robot = robot
        if robot.footprint_radius is None:
            raise ConfigError(f"{robot.source}: footprint_radius: needed for the maze task")
        MazeTaskBase.__init__(self, settings, robot.control_period, robot.footprint_radius)
        if self.layout.rangefinders is None:
            raise ConfigError(f"{settings.sensors}: a legged robot's laser needs rangefinders")
        try:  # here, not first in a worker, so that the error names the file
            Scanner.from_layout(self.layout.rangefinders)
        except ValueError as e:
            raise ConfigError(f"{settings.sensors}: {e}") from None
        self.world = LeggedWorld(tuple(self.mazes), self.layout, robot, self.n_cycles)
        self.workers = max(1, workers or available_cores())

    def describe(self) -> dict:
        """The simulated robot, as repertoire files record it."""
        return self.robot.describe()

    @property
    def parameter_specs(self) -> tuple[ParameterSpec, ...]:
        """The robot's locomotion parameters (a standard controller's outputs)."""
        return self.robot.gait.parameter_specs()

    #: No perturbed worlds yet (the hexapod's episode applies them; this one does not).
    perturbation_family = None
    controller_type = LeggedController
    runner_type = EpisodeRunner
    worker_init = staticmethod(_init_worker)
    worker_episode = staticmethod(_episode)


def legged_task(robot, settings: MazeTaskSettings, workers: int | None = None) -> LeggedMazeTask:
    """A legged registration's maze task (its ``task`` factory): ``robot.model``'s robot."""
    return LeggedMazeTask(settings, str(robot.model.path()), workers=workers)


__all__ = ["LeggedMazeTask", "legged_task"]
