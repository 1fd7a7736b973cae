"""The recipe steps that make a robot (``robot-from-urdf``, ``design-gait``), registered.

The registration gives a recipe's own robots to its repertoire and arbitrator steps.

A legged robot made by a recipe is declared in ``OUT/robots/NAME.yaml`` (a robot
settings file naming the last model an earlier step wrote, with the episode time its
gait design needs: :func:`~offline_evolution.gait_design.maze_needs.fitted_episode_time`),
and ``OUT/robots`` and the folders of the recipe's ``robot_file`` robots are put first on
this process's ``$EVORBC_ROBOT_PATH`` (docs/your-robot.md, "The quick path"), so that the
runs, their worker processes and the files they write find the robot by name as any
user's.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.config import ConfigError
from offline_evolution.recipes.spec import (
    DesignGaitStep,
    Recipe,
    RepertoireStep,
    RobotFromUrdfStep,
)

#: The design search's checkpoint, after its output's name (``design-gait``'s default).
DESIGN_CHECKPOINT_SUFFIX = ".checkpoint.json"
#: Where a recipe's own legged robots are declared, in its output folder.
ROBOTS_FOLDER = "robots"


def urdf_step_of(recipe: Recipe, name: str) -> RobotFromUrdfStep:
    """The ``robot-from-urdf`` step a ``robot_step`` or ``settings_step`` leads back to."""
    step = recipe.step(name)
    while isinstance(step, DesignGaitStep):
        step = recipe.step(step.settings_step)
    if not isinstance(step, RobotFromUrdfStep):
        raise ConfigError(
            f"{recipe.path}: step {name!r} is a {step.run} step; expected a robot-from-urdf "
            "or design-gait step"
        )
    return step


def robot_name(recipe: Recipe, step: RepertoireStep) -> str:
    """The name of ``step``'s robot (registered, from its file, or made by the recipe)."""
    if step.robot is not None:
        return step.robot
    if step.robot_step is not None:
        return urdf_step_of(recipe, step.robot_step).name
    from evorbc_ros.robots.settings_robots import read_robot_file

    robot = read_robot_file(step.robot_file)
    if robot is None:
        raise ConfigError(f"{step.robot_file}: robot_file: not a robot settings file (no kind)")
    return robot.name


def register_robots(recipe: Recipe, out: Path) -> None:
    """Declare the recipe's robots made so far and put their folders on the robot path."""
    from evorbc_ros.robots import registry
    from evorbc_ros.robots.settings_robots import PATH_VARIABLE
    from offline_evolution.gait_design.maze_needs import fitted_episode_time
    from sim_bridge.legged.urdf_settings import declaration_text

    folders = []
    for step in recipe.steps:
        if not isinstance(step, RepertoireStep):
            continue
        if step.robot_file is not None:
            folders.append(str(Path(step.robot_file).parent))
        elif step.robot_step is not None and (out / recipe.step(step.robot_step).out).is_file():
            name = urdf_step_of(recipe, step.robot_step).name
            model = recipe.step(step.robot_step).out
            path = out / ROBOTS_FOLDER / f"{name}.yaml"
            seconds, why = fitted_episode_time(_design_record(out / model))
            description = f"{name}, made by {recipe.recipe}"
            text = declaration_text(name, f"../{model}", description, seconds, why)
            if not path.is_file() or path.read_text() != text:
                path.parent.mkdir(exist_ok=True)
                atomic_write_text(path, text)
            folders.append(str(path.parent))
    if not folders:
        return
    held = [f for f in os.environ.get(PATH_VARIABLE, "").split(os.pathsep) if f]
    os.environ[PATH_VARIABLE] = os.pathsep.join(dict.fromkeys(folders + held))
    registry.reset()  # the registry read the robot path before; read it again


def _design_record(model: Path) -> dict | None:
    """The ``design_search`` record of a legged settings file (None: no search made it)."""
    from evorbc_ros.config import load_yaml_mapping

    record = load_yaml_mapping(model).get("design_search")
    return record if isinstance(record, dict) else None


def run_robot_from_urdf(step: RobotFromUrdfStep, out: Path, say: Callable[[str], None]) -> None:
    """``evorbc-evolve robot-from-urdf`` for ``step``, into the output folder."""
    from offline_evolution.commands.robot_from_urdf import turn_rad, write_robot_files

    write_robot_files(step.urdf, out, step.name, step.up, turn_rad(step.turn), step.stance, say)


def run_design_gait(
    recipe: Recipe, step: DesignGaitStep, out: Path, budget: str, say: Callable[[str], None]
) -> None:
    """``evorbc-evolve design-gait`` for ``step`` (its own budget, or the small one)."""
    from offline_evolution.gait_design.objective import BUDGETS
    from offline_evolution.gait_design.run import design_gait
    from offline_evolution.recipes.budget import SMALL_DESIGN
    from offline_evolution.runs.frame import StopOnSignal, explained, listening

    search = SMALL_DESIGN if budget == "small" else BUDGETS[step.budget]
    name = "small" if budget == "small" else step.budget
    stop = StopOnSignal("design")
    with explained("design"), listening(stop):
        design_gait(
            out / recipe.step(step.settings_step).out,
            out / step.out,
            step.seed,
            name,
            search,
            progress=say,
            should_stop=stop,
        )
