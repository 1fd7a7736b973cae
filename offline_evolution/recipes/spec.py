"""Recipe files (``config/recipes/*.yaml``): the steps that make a shipped controller.

A recipe names its steps in order. Each step runs one kind of job and writes one file,
``out``, into the run's output folder:

* ``repertoire``: MAP-Elites for a ``robot`` with a ``settings`` file and a ``seed``;
* ``arbitrator``: NEAT with a run ``settings`` file (its NEAT file and task unless
  ``neat`` or ``task`` are given), a ``seed`` and optionally ``generations``, over the
  ``repertoire`` an earlier step wrote (or ``repertoire_file``), and optionally warm
  started from the arbitrator an earlier step wrote (``init_from``, or ``init_from_file``);
* ``copy``: the output of an earlier step under another name (a shipped file that was
  renamed: the name is recorded in the files that read it);
* ``robot-from-urdf``: a legged robot's settings derived from a ``urdf``
  (``evorbc-evolve robot-from-urdf``); its ``out`` is ``NAME-model.yaml``;
* ``design-gait``: the gait design search (``evorbc-evolve design-gait``) over the
  settings an earlier step wrote (``settings_step``), at a ``budget`` with a ``seed``;
* ``settled``: the settled outcomes of a 4WS or legged ``repertoire`` an earlier step wrote (or
  ``repertoire_file``), for the arbitrator node's adaptation (``evorbc-evolve settled``).

A repertoire step's robot is a registered ``robot``, a robot settings file
(``robot_file``, its folder put on ``$EVORBC_ROBOT_PATH`` for the run) or the legged
robot of an earlier ``robot-from-urdf`` or ``design-gait`` step (``robot_step``): the
quick path (docs/your-robot.md, "The quick path").

Relative paths in a recipe are from the recipe file's folder. A step may state what the
shipped file is: its ``sha256`` and ``content_sha256`` (:mod:`.digest`), and, where the
recipe is known to make something else, ``recipe_content_sha256`` and a ``note`` saying
why; the full budget compares its outputs with them (docs/design.md, "Recipes").
"""

from __future__ import annotations

import dataclasses
import os
import re
from dataclasses import dataclass
from pathlib import Path

from evorbc_ros.config import ConfigError, build_settings, load_yaml_mapping, setting
from evorbc_ros.robots.registry import ROBOT_NAMES

#: Step kinds, by the value of a step's ``run`` key.
KINDS = ("repertoire", "arbitrator", "copy", "robot-from-urdf", "design-gait", "settled")
#: What a step name and an output name may be: a plain file name, no folders.
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}")
_SHA256 = re.compile(r"[0-9a-f]{64}")
_MAX_STEPS = 20


@dataclass(frozen=True, kw_only=True)
class _Common:
    """Keys every step has."""

    step: str = setting(doc="the step's name; later steps refer to its output by it")
    run: str = setting(doc="what the step runs", choices=KINDS)
    out: str = setting(doc="the file it writes in the output folder (a plain name)")
    sha256: str | None = setting(None, doc="sha256 of the shipped file's bytes")
    content_sha256: str | None = setting(
        None, doc="sha256 of the shipped file's content without wall-clock times"
    )
    recipe_content_sha256: str | None = setting(
        None, doc="content_sha256 this recipe makes, where it is not the shipped file's"
    )
    note: str = setting("", doc="why the recipe makes another file than the shipped one")
    shipped: str | None = setting(
        None, doc="the shipped file, so that a full run that differs says where"
    )


@dataclass(frozen=True, kw_only=True)
class RepertoireStep(_Common):
    """``evorbc-evolve repertoire --robot ROBOT --config SETTINGS --seed SEED``."""

    robot: str | None = setting(None, doc="robot type", choices=ROBOT_NAMES)
    robot_file: str | None = setting(None, doc="a robot settings file, if not registered")
    robot_step: str | None = setting(None, doc="the earlier step whose legged robot it is")
    settings: str | None = setting(None, doc="MAP-Elites settings file (default: the robot's)")
    seed: int = setting(doc="random seed", minimum=0)
    iterations: int | None = setting(None, doc="iterations (default: the settings')", minimum=0)
    initial_batch: int | None = setting(None, doc="S_G (default: the settings')", minimum=1)
    batch_size: int | None = setting(None, doc="S_B (default: the settings')", minimum=1)
    archive: str | None = setting(None, doc="grid or cvt (default: the settings')")
    variation: str | None = setting(None, doc="paper or iso_line_dd (default: the settings')")


@dataclass(frozen=True, kw_only=True)
class ArbitratorStep(_Common):
    """``evorbc-evolve arbitrator`` over a repertoire, optionally warm started."""

    settings: str = setting(doc="arbitrator run settings file")
    seed: int = setting(doc="random seed", minimum=0)
    repertoire: str | None = setting(None, doc="the earlier step whose repertoire it uses")
    repertoire_file: str | None = setting(None, doc="a repertoire file, if not a step's")
    neat: str | None = setting(None, doc="NEAT settings file (default: the settings')")
    task: str | None = setting(None, doc="task settings file (default: the settings')")
    generations: int | None = setting(None, doc="generations (default: the settings')", minimum=1)
    robot_episode_time: bool | None = setting(
        None, doc="true: episodes as long as the robot's registration declares, not the task's"
    )
    init_from: str | None = setting(None, doc="the earlier step whose network it starts from")
    init_from_file: str | None = setting(None, doc="an arbitrator file to start from")


@dataclass(frozen=True, kw_only=True)
class CopyStep(_Common):
    """An earlier step's output under another name."""

    source: str = setting(doc="the earlier step whose output is copied")


@dataclass(frozen=True, kw_only=True)
class RobotFromUrdfStep(_Common):
    """``evorbc-evolve robot-from-urdf URDF --out OUT --name NAME``."""

    urdf: str = setting(doc="the URDF (relative to the recipe, absolute, or pybullet_data:PATH)")
    name: str = setting(doc="the robot's name; out must be NAME-model.yaml")
    up: str | None = setting(
        None, doc="the URDF's up axis", choices=("z", "y", "x", "-z", "-y", "-x")
    )
    turn: tuple[float, ...] | None = setting(
        None, doc="deg: roll, pitch, yaw standing the URDF Z-up facing +x (overrides up)"
    )
    stance: float | None = setting(
        None, doc="standing height as a share of the straight leg", minimum=0.2, maximum=0.99
    )


@dataclass(frozen=True, kw_only=True)
class DesignGaitStep(_Common):
    """``evorbc-evolve design-gait SETTINGS --out OUT --seed SEED --budget BUDGET``."""

    settings_step: str = setting(doc="the earlier step whose legged settings it designs")
    seed: int = setting(doc="random seed", minimum=0)
    budget: str = setting("quick", doc="the search's budget", choices=("quick", "full"))


@dataclass(frozen=True, kw_only=True)
class SettledStep(_Common):
    """``evorbc-evolve settled REPERTOIRE --out OUT``."""

    repertoire: str | None = setting(None, doc="the earlier step whose repertoire it uses")
    repertoire_file: str | None = setting(None, doc="a repertoire file, if not a step's")


_CLASSES = {
    "repertoire": RepertoireStep,
    "arbitrator": ArbitratorStep,
    "copy": CopyStep,
    "robot-from-urdf": RobotFromUrdfStep,
    "design-gait": DesignGaitStep,
    "settled": SettledStep,
}
Step = RepertoireStep | ArbitratorStep | CopyStep | RobotFromUrdfStep | DesignGaitStep | SettledStep


@dataclass(frozen=True)
class Recipe:
    """A recipe file, its steps checked and its paths made absolute."""

    recipe: str  # what it makes, in a few words
    steps: tuple[Step, ...]
    path: Path  # the recipe file

    def step(self, name: str) -> Step:
        """The step called ``name``."""
        return next(s for s in self.steps if s.step == name)

    def as_dict(self) -> dict:
        """Plain data: what a run's output folder records to refuse mixing two recipes."""
        return {"recipe": self.recipe, "steps": [dataclasses.asdict(s) for s in self.steps]}


def load_recipe(path: str | os.PathLike) -> Recipe:
    """Read and check the recipe file ``path``.

    Raises:
        ConfigError: one line naming the file, the step and the key: an unknown key (with
            a suggestion), a missing or bad value, a name used twice, a reference to a step
            that is not earlier, or a file that does not exist.
    """
    source = str(path)
    data = load_yaml_mapping(path)
    top = {k: v for k, v in data.items() if k != "steps"}
    build_settings(_Top, top, source)
    raw = data.get("steps")
    if not isinstance(raw, list) or not raw:
        raise ConfigError(f"{source}: steps must be a list of at least one step")
    if len(raw) > _MAX_STEPS:
        raise ConfigError(f"{source}: steps: at most {_MAX_STEPS} steps, got {len(raw)}")
    folder = Path(path).resolve().parent
    steps: list[Step] = []
    for i, item in enumerate(raw):
        steps.append(_step(item, f"{source}: steps[{i}]", folder, steps))
    return Recipe(recipe=data["recipe"], steps=tuple(steps), path=Path(path).resolve())


@dataclass(frozen=True)
class _Top:
    recipe: str = setting(doc="what the recipe makes, in a few words")
    steps: tuple = setting((), doc="the steps, in order")


def _step(item, where: str, folder: Path, earlier: list[Step]) -> Step:
    """One step of a recipe, checked against the steps before it."""
    if not isinstance(item, dict):
        raise ConfigError(f"{where}: expected a mapping (step:, run:, ...), got {item!r}")
    kind = item.get("run")
    if kind not in _CLASSES:
        raise ConfigError(f"{where}: run must be one of {', '.join(KINDS)}; got {kind!r}")
    name = item.get("step")
    label = f"{where} ({name})" if isinstance(name, str) else where
    step = build_settings(_CLASSES[kind], item, label)
    for key in ("step", "out"):
        if not _NAME.fullmatch(getattr(step, key)):
            raise ConfigError(
                f"{label}: {key} must be a plain name (letters, digits, '.', '_', '-'), "
                f"got {getattr(step, key)!r}"
            )
    for key in ("sha256", "content_sha256", "recipe_content_sha256"):
        value = getattr(step, key)
        if value is not None and not _SHA256.fullmatch(value):
            raise ConfigError(f"{label}: {key} must be 64 lowercase hex digits, got {value!r}")
    for other in earlier:
        if other.step == step.step:
            raise ConfigError(f"{label}: step {step.step!r} is named twice")
        if other.out == step.out:
            raise ConfigError(f"{label}: out {step.out!r} is also step {other.step!r}'s")
    return _resolved(step, label, folder, earlier)


def _resolved(step: Step, label: str, folder: Path, earlier: list[Step]) -> Step:
    """``step`` with its file keys made absolute and its step references checked."""
    names = [s.step for s in earlier]
    files = {}
    if isinstance(step, RobotFromUrdfStep):
        if step.out != f"{step.name}-model.yaml":
            raise ConfigError(f"{label}: out must be {step.name}-model.yaml (NAME-model.yaml)")
        if not step.urdf.startswith("pybullet_data:"):
            files["urdf"] = str((folder / step.urdf).resolve())
        if step.turn is not None and len(step.turn) != 3:
            raise ConfigError(f"{label}: turn must be 3 angles in deg (roll, pitch, yaw)")
    for key in (
        "settings",
        "neat",
        "task",
        "repertoire_file",
        "init_from_file",
        "shipped",
        "robot_file",
    ):
        value = getattr(step, key, None)
        if value is None:
            continue
        target = folder / value
        if not target.is_file():
            raise ConfigError(
                f"{label}: {key}: no such file {target} (relative paths are from the "
                "recipe's folder)"
            )
        files[key] = str(target.resolve())
    pairs = (
        (("repertoire", "repertoire_file"), True),
        (("init_from", "init_from_file"), False),
        (("robot", "robot_file", "robot_step"), True),
    )
    for keys, needed in pairs:
        if not hasattr(step, keys[0]):
            continue
        given = [k for k in keys if getattr(step, k) is not None]
        if len(given) > 1 or (needed and not given):
            raise ConfigError(f"{label}: give one of {', '.join(keys)}")
    for key in ("repertoire", "init_from", "source", "robot_step", "settings_step"):
        value = getattr(step, key, None)
        if value is not None and value not in names:
            known = ", ".join(names) or "none"
            raise ConfigError(
                f"{label}: {key}: {value!r} is not an earlier step (earlier steps: {known})"
            )
    return dataclasses.replace(step, **files)
