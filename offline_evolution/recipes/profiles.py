"""Profiles (``config/profiles/*.yaml``): the recipe from a robot to a controller.

``evorbc-evolve from-robot SOURCE --out DIR --profile quick|full`` writes, into ``DIR``,
a recipe (``recipe.yaml``) and the run and task settings of its arbitrator step
(``profile/``), then runs it (:mod:`.runner`): resumable, seeded, one output folder.

* SOURCE a URDF (``.urdf`` or ``pybullet_data:PATH``): ``robot-from-urdf``,
  ``design-gait`` at the profile's budget, the repertoire with the profile's ``legged``
  budget, the arbitrator from the A1's run and task settings (which the derived robot
  uses) with the profile's ``legged`` overrides and generated-maze training, its
  episodes as long as the designed gait needs (``robot_episode_time``);
* SOURCE a robot settings file (docs/your-robot.md): the repertoire and arbitrator of its
  own settings, with the profile's ``wheeled`` (diff_drive, four_ws) or ``legged`` ones.

docs/your-robot.md, "The quick path".
"""

from __future__ import annotations

import re
from pathlib import Path

import yaml

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.config import ConfigError, config_dir, load_yaml_mapping
from offline_evolution.recipes.budget import portable_task

PROFILES = ("quick", "full")
#: Run-settings keys a profile may set (the rest are the robot's own).
RUN_KEYS = (
    "generations",
    "hall_of_fame",
    "post_samples",
    "nominal_watch",
    "snapshot_every",
    "post_rule",
)
#: The arbitrator settings of a robot from a URDF (its declaration names the A1's).
LEGGED_RUN = "arbitrator/a1.yaml"


def profile_path(name: str) -> Path:
    """``config/profiles/NAME.yaml``."""
    return config_dir() / "profiles" / f"{name}.yaml"


def is_urdf(source: str) -> bool:
    """Whether SOURCE names a URDF rather than a robot settings file."""
    return source.startswith("pybullet_data:") or source.lower().endswith(".urdf")


def write_profile_recipe(
    source: str,
    profile: str,
    out: Path,
    seed: int,
    name: str | None = None,
    standing: dict | None = None,
) -> Path:
    """Write the profile's recipe for ``source`` into ``out``; return the recipe file.

    Args:
        source: a URDF (``.urdf``, ``pybullet_data:PATH``) or a robot settings file (.yaml).
        profile: ``quick`` or ``full``.
        out: the output folder (exists).
        seed: of every step.
        name: a URDF robot's name (default: the URDF file's stem, then ``-urdf``, so that
            it never takes a built-in robot's name).
        standing: a URDF's ``up``, ``turn`` (deg, roll pitch yaw) and ``stance``, those
            given, for its ``robot-from-urdf`` step.

    Raises:
        ConfigError: one line: a source that is neither, a robot file that does not load,
            standing options for a robot settings file.
    """
    spec = load_yaml_mapping(profile_path(profile))
    folder = out / "profile"
    folder.mkdir(exist_ok=True)
    steps: list[dict] = []
    if is_urdf(source):
        urdf = source if source.startswith("pybullet_data:") else str(Path(source).resolve())
        if not source.startswith("pybullet_data:") and not Path(source).is_file():
            raise ConfigError(f"{source}: no such URDF file")
        stem = re.sub(r"[^A-Za-z0-9._+-]", "-", Path(source.split(":")[-1]).stem)
        name = name or f"{stem}-urdf"
        family, run_file = "legged", config_dir() / LEGGED_RUN
        steps += [
            {
                "step": "urdf",
                "run": "robot-from-urdf",
                "urdf": urdf,
                "name": name,
                **{k: list(v) if k == "turn" else v for k, v in (standing or {}).items()},
                "out": f"{name}-model.yaml",
            },
            {
                "step": "design",
                "run": "design-gait",
                "settings_step": "urdf",
                "seed": seed,
                "budget": spec["design_gait"],
                "out": f"{name}-designed.yaml",
            },
        ]
        robot = {"robot_step": "design"}
    elif source.lower().endswith((".yaml", ".yml")) and Path(source).is_file():
        from evorbc_ros.robots.settings_robots import read_robot_file

        if standing:
            given = ", ".join(f"--{k}" for k in standing)
            raise ConfigError(f"{given}: only for a URDF; {source} is a robot settings file")
        declared = read_robot_file(source)
        if declared is None:
            raise ConfigError(f"{source}: not a robot settings file (no kind key)")
        family = "legged" if declared.family == "legged" else "wheeled"
        run_file = _config_file(declared.settings.arbitrator)
        robot = {"robot_file": str(Path(source).resolve())}
        name = declared.name
    else:
        raise ConfigError(
            f"{source}: expected a URDF (.urdf or pybullet_data:PATH) or a robot settings "
            "file (.yaml with a kind key)"
        )
    steps.append(
        {
            "step": "repertoire",
            "run": "repertoire",
            **robot,
            "seed": seed,
            "out": f"{name}.repertoire.json",
            **spec["repertoire"][family],
        }
    )
    overrides = dict(spec["arbitrator"][family])
    run = _arbitrator_settings(run_file, overrides, folder)
    steps.append(
        {
            "step": "arbitrator",
            "run": "arbitrator",
            "repertoire": "repertoire",
            "settings": str(run),
            "seed": seed,
            # A URDF robot's episode is as long as its designed gait needs
            # (gait_design/maze_needs.py, fitted_episode_time), not the A1's task's 30 s.
            **({"robot_episode_time": True} if is_urdf(source) else {}),
            "out": f"{name}.arbitrator.json",
        }
    )
    recipe = {"recipe": f"{name} at the {profile} profile", "steps": steps}
    path = out / "recipe.yaml"
    text = f"# Written by evorbc-evolve from-robot {source} --profile {profile}\n"
    atomic_write_text(path, text + yaml.safe_dump(recipe, sort_keys=False))
    return path


def _config_file(value: str) -> Path:
    """A registration's settings file: absolute, or relative to ``config/``."""
    path = Path(value)
    return path if path.is_absolute() else config_dir() / path


def _arbitrator_settings(run_file: Path, overrides: dict, folder: Path) -> Path:
    """The robot's run settings with the profile's overrides and generated-maze training."""
    from offline_evolution.arbitrator.settings import load_run_settings

    settings = load_run_settings(run_file)
    data = load_yaml_mapping(run_file)
    neat = overrides.pop("neat", None)
    neat_path = (profile_path("quick").parent / neat).resolve() if neat else settings.neat_path()
    task = portable_task(settings.task_path())
    if "training" in overrides:
        task["training"] = overrides.pop("training")
    data.update({k: v for k, v in overrides.items() if k in RUN_KEYS})
    task_file = folder / "task.yaml"
    atomic_write_text(task_file, yaml.safe_dump(task, sort_keys=False))
    data["neat"], data["task"] = str(neat_path), str(task_file)
    run = folder / "run.yaml"
    atomic_write_text(run, yaml.safe_dump(data, sort_keys=False))
    return run
