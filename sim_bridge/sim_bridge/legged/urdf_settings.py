"""The settings files of a legged robot read from its URDF, every value commented.

:func:`settings_text` writes the robot's settings file (docs/legged.md, the A1's
``config/robots/a1.yaml`` form) from a :class:`~sim_bridge.legged.urdf_reader.DerivedRobot`;
:func:`declaration_text` the robot file that registers it on ``$EVORBC_ROBOT_PATH``. The
values the URDF cannot give (servo gain, physics rate, gait frequency, ranges) start from
the A1's shipped design (docs/a1.md), scaled where a law says how; the gait design search
tunes them. Units: m, s, deg in ``*_deg`` keys, N m.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

from sim_bridge.legged.urdf_reader import KNEE_HALF_RANGE, DerivedRobot, Leg

#: The A1's shipped design (docs/a1.md): the reference the other values scale from.
A1_LEG = 0.4  # m, thigh + shank
A1_FREQUENCY = 2.5  # Hz
A1_GAIN = 10.0  # 1/s
A1_RATE = 100.0  # Hz
#: Gaits outrun the swing's sweep (hops, bounds): the A1's reached 0.75 m/s against 0.58 by
#: the sweep alone (docs/a1.md, "Repertoire").
SPEED_MARGIN = 1.5


@dataclass(frozen=True)
class Measured:
    """What :func:`sim_bridge.legged.urdf_check.stand_check` measured in the simulation."""

    reach_radius: float  # m, every collision shape at rest
    height: float  # m, the root link's height after standing
    tilt: float  # deg, largest tilt while standing
    seconds: float  # s stood


def _deg(value: float, digits: int = 1) -> str:
    return f"{round(math.degrees(value), digits) + 0.0:g}"


def _xyz(v) -> str:
    return "(" + ", ".join(f"{x:+.3f}" for x in v) + ")"


def frequency(legs: list[Leg]) -> float:
    """Hz: the A1's 2.5 Hz at equal Froude number (f ~ sqrt(g / leg)), to 0.05 Hz."""
    leg = max(sum(leg.segments) for leg in legs)
    return round(20.0 * A1_FREQUENCY * math.sqrt(A1_LEG / leg)) / 20.0


def speed_bound(legs: list[Leg], hz: float) -> float:
    """m/s: the widest swing's sweep per cycle, 2 h tan(swing) x frequency, with margin."""
    sweep = max(2.0 * -leg.foot_stand[2] * math.tan(leg.swing_half) for leg in legs)
    return math.ceil(20.0 * SPEED_MARGIN * sweep * hz) / 20.0


def _limit(legs: list[Leg], model, field: str) -> float | None:
    values = [
        getattr(model.joints[j], field)
        for leg in legs
        for j, role in zip(leg.joints, leg.roles, strict=True)
        if role != "abduction"
    ]
    values = [v for v in values if v]
    return min(values) if values else None


def _urdf_value(derived: DerivedRobot, turned_name: str | None) -> str:
    if turned_name:
        return turned_name
    path = derived.model.path.resolve()
    try:
        import pybullet_data

        return f"pybullet_data:{path.relative_to(Path(pybullet_data.getDataPath()).resolve())}"
    except ValueError:
        return str(path)


def settings_text(
    derived: DerivedRobot, name: str, measured: Measured | None, turned_name: str | None
) -> str:
    """The robot's settings file (YAML), every derived value with how it was derived.

    Args:
        derived: what the URDF said.
        name: the robot's name.
        measured: the standing check's measurements (footprint), or None to leave the
            footprint unset.
        turned_name: the turned copy's file name (beside the settings file) when the URDF
            is not Z-up, else None.

    """
    hz = frequency(derived.legs)
    lines = [
        *_header(derived, name, turned_name),
        *_legs(derived),
        *_oscillators(derived.legs),
        *_joints(derived.legs),
        *_gait_and_servo(derived, hz),
        *_physics(),
        *_bounds(derived.legs, hz, measured),
    ]
    return "\n".join(lines) + "\n"


def _header(derived: DerivedRobot, name: str, turned_name: str | None) -> list[str]:
    """The file's opening comment, its name and its URDF."""
    model = derived.model
    lines = [
        f"# {name}: a legged robot read from {model.path.name} by `evorbc-evolve robot-from-urdf`",
        '# (docs/legged.md, "From a URDF"), from the URDF alone: every value says how it was',
        "# derived. Override any of them; the servo, ranges, frequency and physics rate start",
        "# from the A1's shipped design (docs/a1.md) for the gait design search to tune.",
        "# Units: m, s, rad (deg where a key ends in _deg), N m. Robot frame: x forward, y left,",
        f"# z up. Up axis of the URDF: {derived.up} ({derived.turn_given}); mass "
        f"{derived.mass:.2f} kg.",
        f"name: {name}",
    ]
    if turned_name:
        lines.append(
            f"urdf: {turned_name}  # {model.path}, its root frame turned {derived.up}-up to z-up"
        )
    else:
        lines.append(f"urdf: {_urdf_value(derived, None)}")
    return lines


def _legs(derived: DerivedRobot) -> list[str]:
    """The base and foot links, and each leg as read (comments)."""
    legs = derived.legs
    feet = ", ".join(leg.foot for leg in legs)
    lines = [
        "links:",
        f"  base: {derived.base}  # the URDF's root link",
        f"  feet: [{feet}]  # per leg, the leaf link below its last moving joint",
        "# Legs, read from the URDF's tree (movable joints from the base to each foot); side by",
        "# the thigh joint's lateral offset, mirror the leg nearest its mirror image. Standing:",
        f"# each foot straight below its thigh joint at {derived.stance:g} x the straight leg",
        "# (the A1's stance); positions in m from the root link's origin, robot frame.",
    ]
    for leg in legs:
        roles = ", ".join(f"{j} ({r})" for j, r in zip(leg.joints, leg.roles, strict=True))
        lines += [
            f"#   {leg.name}: {leg.side}, mirror {leg.mirror}; {roles}",
            f"#     thigh joint at {_xyz(leg.hip)}, thigh {leg.segments[0]:.3f} m, shank "
            f"{leg.segments[1]:.3f} m; standing foot at {_xyz(leg.foot_stand)}",
        ]
        lines += [f"#     note: {note}" for note in leg.notes]
    return lines


def _oscillators(legs: list[Leg]) -> list[str]:
    """The evolved swing and knee of each leg, with their ranges in degrees."""
    lines = [
        "# Evolved (eq. 10-11), per leg: the swing (the hip-to-foot line's angle from the",
        "# vertical, positive backwards) and the knee (its joint angle, sign turned so that",
        "# positive turns about +y). Swing +-25 deg and knee +-15 deg about standing are the",
        f"# A1's ranges (angles do not scale with size), cut to the URDF's limits. "
        f"{1 + 6 * len(legs)} genes.",
        "oscillators:",
    ]
    by_name = {leg.name: leg for leg in legs}
    for leg in legs:
        # Mirror pairs take the left leg's ranges: the mirror check wants them equal.
        source = leg if leg.side == "left" else by_name[leg.mirror]
        s = source.signs["knee"]
        knee_low, knee_high = sorted(q * s for q in source.knee_range)
        swing = _deg(source.swing_half)
        lines += [
            f"  {leg.name}_swing: {{range_deg: [-{swing}, {swing}], mirror: {leg.mirror}_swing}}",
            f"  {leg.name}_knee: {{range_deg: [{_deg(knee_low)}, {_deg(knee_high)}], mirror: "
            f"{leg.mirror}_knee}}  # standing {_deg(source.knee_stand * s)} +- "
            f"{_deg(KNEE_HALF_RANGE, 0)}",
        ]
    return lines


def _joints(legs: list[Leg]) -> list[str]:
    """Every actuated joint's drive, in command order."""
    lines = [
        "# Every actuated joint in command order: constant + sum(coefficient x oscillator).",
        "# The thigh follows the swing and the knee so that the foot stays under the hip: the",
        "# thigh angle doing so, found by forward kinematics over the knee's range, fitted by a",
        "# line (the A1's thigh = swing - knee / 2 for its equal 0.2 m segments); the fit's",
        "# largest error is given. The hip abduction is held, as the A1's (docs/a1.md).",
        "joints:",
    ]
    for leg in legs:
        for joint, role in zip(leg.joints, leg.roles, strict=True):
            lines.append(f"  {joint}: {_drive(leg, role)}")
    return lines


def _gait_and_servo(derived: DerivedRobot, hz: float) -> list[str]:
    """The gait frequency (Hz) and the servo: gain (1/s), speed (rad/s) and torque (N m)."""
    model, legs = derived.model, derived.legs
    longest = max(sum(leg.segments) for leg in legs)  # m, thigh + shank
    lines = [
        "gait:",
        f"  frequency_hz: {hz:g}  # the A1's {A1_FREQUENCY:g} Hz at equal Froude number: "
        f"x sqrt({A1_LEG:g} m / {longest:.3f} m leg)",
        "servo:  # v = clip(gain x error, +-max_velocity), torque <= max_torque",
        f'  gain: {A1_GAIN:g}  # 1/s, the A1\'s (docs/a1.md, "Gait design")',
    ]
    velocity = _limit(legs, model, "velocity")
    if velocity:
        lines.append(
            f"  max_velocity: {velocity:g}  # rad/s, the URDF's least thigh/knee <limit velocity>"
        )
    else:
        lines.append("  max_velocity: 21.0  # rad/s, the A1's: the URDF gives no <limit velocity>")
    torque = _limit(legs, model, "effort")
    if torque:
        lines.append(f"  max_torque: {torque:g}  # N m, the URDF's least thigh/knee effort")
    else:
        weight = derived.mass * 9.81 * longest  # N m: the whole weight at one leg's length
        lines.append(
            f"  max_torque: {math.ceil(weight):g}  # N m: the URDF gives no <limit effort>; the "
            "whole weight at one leg's length"
        )
    return lines


def _physics() -> list[str]:
    """Physics rate, solver, friction, tilts, control period: the A1's but the discard tilt."""
    from sim_bridge.legged.gait_measures import POOL_TILT  # imports PyBullet: here only

    rate_steps = "control_period and settle_time are whole steps"
    return [
        "physics:",
        f'  rate_hz: {A1_RATE:g}  # the A1\'s (docs/a1.md, "Physics rate"); {rate_steps}',
        "  solver_iterations: 50",
        "  friction: 1.0",
        "  settle_time: 1.0  # s standing before the rest state every primitive starts from",
        "  wall_height: 0.4  # m",
        "tilt:",
        # The design search's switching measure chains only primitives steady within
        # POOL_TILT; a repertoire keeping more tilted ones falls in its mazes where that
        # measure said it would not (the Laikago: 42 of a 45-deg repertoire's 118
        # primitives fell held 30 s, 16 of the 92 within 20 deg; docs/your-robot.md).
        f"  discard_deg: {math.degrees(POOL_TILT):g}  # eq. 6: a primitive tilting more is "
        "discarded; the design search's steady pool (the A1's and hexapod's: 45)",
        "  fallen_deg: 90  # an episode ends: the robot fell over",
        "control_period: 0.1  # s",
    ]


def _bounds(legs: list[Leg], hz: float, measured: Measured | None) -> list[str]:
    """The footprint (m, when measured), the speed bound (m/s) and self-collision."""
    lines = []
    if measured is not None:
        lines.append(
            f"footprint_radius: {math.ceil(100.0 * measured.reach_radius) / 100.0:.2f}  # m: every "
            f"collision shape at rest ({measured.reach_radius:.3f} m, LeggedSim.reach_radius); "
            f"standing {measured.seconds:g} s it kept {measured.height:.3f} m and tilted "
            f"{measured.tilt:.1f} deg at most"
        )
    return [
        *lines,
        f"speed_bound: {speed_bound(legs, hz):g}  # m/s: {SPEED_MARGIN:g} x the widest swing's "
        "sweep, 2 h tan(swing) x frequency",
        "self_collision: false  # the A1's",
    ]


def _drive(leg: Leg, role: str) -> str:
    if role == "abduction":
        return f"{{constant_deg: {_deg(leg.abduction, 2)}}}  # held, as the A1's"
    s_knee, s_thigh = leg.signs["knee"], leg.signs["thigh"]
    if role == "knee":
        return f"{{{leg.name}_knee: {s_knee}}}"
    c0, c1 = leg.coupling
    return (
        f"{{constant_deg: {_deg(c0, 2)}, {leg.name}_swing: {s_thigh}, {leg.name}_knee: "
        f"{round(c1 * s_knee, 4):g}}}  # fit error {math.degrees(leg.coupling_error):.3f} deg"
    )


def declaration_text(
    name: str,
    model_file: str,
    description: str,
    episode_time: float = 30.0,
    episode_note: str = "the A1's",
) -> str:
    """The robot file registering the robot (docs/legged.md, "Registering it").

    Its repertoire, arbitrator, NEAT, task, sensor and maze settings are the A1's, named
    ``config:NAME`` (evorbc's ``config/`` wherever it is installed,
    :data:`evorbc_ros.settings_paths.SHIPPED_PREFIX`): copy one beside it to change it.
    ``episode_time`` (s) is the A1's unless a gait design fitted it (``episode_note``
    says how, as a comment); the standard-NEAT baseline's extra generations follow it
    (the A1's repertoire evaluations, 1.025 M x 2 s, over population 150 x an episode).
    """
    equal_budget = int(1_025_000 * 2.0 / (150 * float(episode_time)))
    return (
        f'# {name}: the robot file registering {model_file} (docs/legged.md, "Registering it").\n'
        "# Put this folder on $EVORBC_ROBOT_PATH. The search, sensor and maze settings are the\n"
        "# A1's, from evorbc's config/ (config:NAME, wherever evorbc is installed): copy one\n"
        "# beside this file and name it without config: to change it.\n"
        "kind: legged\n"
        f"model: {model_file}\n"
        f"description: {json.dumps(description)}\n"  # a YAML string
        "settings:\n"
        "  repertoire: config:repertoire/a1.yaml\n"
        "  arbitrator: config:arbitrator/a1.yaml\n"
        "  neat: config:neat/a1.ini\n"
        "  task: config:tasks/maze-a1.yaml\n"
        "sensors: config:sensors/a1.yaml\n"
        "maze: a1\n"
        f"episode_time: {float(episode_time)!r}  # s, {episode_note}\n"
        f"equal_budget_generations: {equal_budget}  # 1.025M x 2 s over 150 x "
        f"{float(episode_time):g} s, as the A1's\n"
    )
