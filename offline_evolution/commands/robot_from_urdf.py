"""``evorbc-evolve robot-from-urdf``: a legged robot's settings files read from its URDF."""

from __future__ import annotations

import argparse
import math
import re
from pathlib import Path

from offline_evolution.commands.common import positive_float
from offline_evolution.runs.errors import UserError

#: A robot's name: letters, digits and . _ + -, starting with a letter.
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9._+-]*")


def add_parsers(sub) -> None:
    """Register ``robot-from-urdf``."""
    p = sub.add_parser(
        "robot-from-urdf",
        help="write a legged robot's settings files, every value derived from its URDF",
        description="Read a legged robot's URDF: its up axis, base and foot links, legs with "
        "their left/right mirrors, joint roles and limits, standing pose, foot positions and "
        "the thigh/knee coupling keeping each foot under its hip. Write NAME-model.yaml (the "
        "settings, every derived value commented), NAME.yaml (the robot file for "
        "$EVORBC_ROBOT_PATH) and, for a URDF that is not Z-up, NAME.urdf (turned Z-up), then "
        "stand the robot 2 s in PyBullet and report (docs/legged.md, 'From a URDF').",
    )
    p.add_argument("urdf", metavar="URDF", help="the URDF file, or pybullet_data:PATH")
    p.add_argument("--out", required=True, metavar="DIR", help="folder for the settings files")
    p.add_argument("--name", help="the robot's name (default: the URDF's robot name)")
    p.add_argument(
        "--up",
        choices=("z", "y", "x", "-z", "-y", "-x"),
        help="the URDF's up axis (default z; a URDF whose legs point elsewhere is refused "
        "unless this or --turn says how to stand it)",
    )
    p.add_argument(
        "--turn",
        nargs=3,
        type=float,
        metavar=("ROLL", "PITCH", "YAW"),
        help="deg: the turn (URDF roll, pitch, yaw) that stands the robot Z-up facing +x; "
        "overrides --up",
    )
    p.add_argument(
        "--stance",
        type=positive_float,
        default=None,
        metavar="SHARE",
        help="standing height as a share of the straight leg (default 0.62, the A1's)",
    )
    p.set_defaults(func=cmd_robot_from_urdf)


def _urdf_path(text: str) -> Path:
    from evorbc_ros.config import ConfigError
    from sim_bridge.legged.settings import resolve_urdf

    try:
        return resolve_urdf(text, Path.cwd() / "command-line")
    except ConfigError:
        raise UserError(f"URDF {text}: no such file") from None


def cmd_robot_from_urdf(args: argparse.Namespace) -> int:
    """Derive, write and check the settings; print what was derived."""
    from offline_evolution.commands.mazes import out_folder

    turn = None if args.turn is None else tuple(math.radians(a) for a in args.turn)
    folder = out_folder(args.out, "--out")
    write_robot_files(args.urdf, folder, args.name, args.up, turn, args.stance, print)
    return 0


def write_robot_files(
    urdf: str,
    folder: Path,
    name: str | None = None,
    up: str | None = None,
    turn: tuple[float, float, float] | None = None,
    stance: float | None = None,
    say=print,
) -> Path:
    """Derive a legged robot's settings from ``urdf`` and write them into ``folder``.

    Args:
        urdf: the URDF file, or ``pybullet_data:PATH``.
        folder: an existing folder; NAME-model.yaml, NAME.yaml (and NAME.urdf for a URDF
            that is not Z-up) are written there atomically, the model file last but one.
        name: the robot's name (default: the URDF's).
        up, turn: the URDF's up axis, or the turn (rad, roll pitch yaw) standing it Z-up.
        stance: standing height as a share of the straight leg (default 0.62).
        say: called with each report line.

    Returns:
        The settings file written (``folder / NAME-model.yaml``).

    Raises:
        UserError, ConfigError: one line saying what to set.
    """
    from evorbc_ros.atomic_io import atomic_write_text
    from sim_bridge.legged.urdf_check import stand_check
    from sim_bridge.legged.urdf_model import turned_urdf_text
    from sim_bridge.legged.urdf_reader import STANCE, read_legged_urdf
    from sim_bridge.legged.urdf_settings import declaration_text, settings_text

    stance = STANCE if stance is None else stance
    if not 0.2 <= stance < 1.0:
        raise UserError(f"--stance {stance:g}: expected a share in [0.2, 1)")
    path = _urdf_path(urdf)
    derived = read_legged_urdf(path, up=up, turn_rpy=turn, stance=stance)
    name = name or re.sub(r"[^A-Za-z0-9._+-]", "-", derived.model.name)
    if not _NAME.fullmatch(name):
        raise UserError(f"--name {name!r}: expected letters, digits and . _ + - (a letter first)")
    model_file = folder / f"{name}-model.yaml"
    turned = None
    if derived.turned:
        turned = f"{name}.urdf"
        note = (
            f"{path} turned {derived.up}-up to z-up by evorbc-evolve robot-from-urdf: its root "
            "link's frame is turned, mesh paths made absolute"
        )
        atomic_write_text(folder / turned, turned_urdf_text(derived.model, derived.turn, note))
    measured = stand_check(settings_text(derived, name, None, turned), model_file)
    atomic_write_text(model_file, settings_text(derived, name, measured, turned))
    legs = len(derived.legs)
    description = f"{name} from {path.name}: {legs} legs, {1 + 6 * legs}-parameter periodic gait"
    atomic_write_text(folder / f"{name}.yaml", declaration_text(name, model_file.name, description))
    say(
        f"{name}: {legs} legs ({', '.join(leg.name for leg in derived.legs)}), base "
        f"{derived.base}, up {derived.up} ({derived.turn_given})"
    )
    for leg in derived.legs:
        c0, c1 = leg.coupling
        say(
            f"  {leg.name}: {leg.side}, mirror {leg.mirror}, foot {leg.foot}; standing knee "
            f"{math.degrees(leg.knee_stand):.1f} deg, thigh = {math.degrees(c0):.2f} deg "
            f"{c1:+.4f} x knee (+ swing)"
        )
    standing = "stands" if measured.tilt < 10.0 else "does NOT stand"
    say(
        f"standing check: it {standing} ({measured.seconds:g} s: height {measured.height:.3f} m, "
        f"tilt at most {measured.tilt:.1f} deg, footprint {measured.reach_radius:.3f} m)"
    )
    say(f"wrote {model_file} and {folder / (name + '.yaml')}; export EVORBC_ROBOT_PATH={folder}")
    return model_file
