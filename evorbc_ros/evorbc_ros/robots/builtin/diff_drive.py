"""The registration of a differential-drive robot (docs/design.md section 19).

A differential-drive robot is declared in a settings file (``kind: diff_drive``,
:mod:`evorbc_ros.robots.settings_robots`); :func:`diff_drive_robot` is what the file's
figures become.
"""

from __future__ import annotations

from evorbc_ros.robots.diff_drive import DiffDriveGeometry
from evorbc_ros.robots.record import Robot, SettingsFiles

#: The topic its command interface publishes: geometry_msgs/Twist, as a TurtleBot3's
#: base, nav2 and ros2_control's diff_drive_controller take it.
COMMAND_TOPICS = ("cmd_vel",)
#: The settings a differential-drive robot file names when it names none (the
#: TurtleBot3 Burger's: paper Table I budgets, mazes it fits).
SETTINGS = SettingsFiles(
    repertoire="repertoire/diff-drive.yaml",
    arbitrator="arbitrator/turtlebot3-burger.yaml",
    neat="neat/4ws.ini",
    task="tasks/maze-turtlebot3-burger.yaml",
)


def diff_drive_robot(name: str, geometry: DiffDriveGeometry, **changes) -> Robot:
    """The registration of a differential-drive robot called ``name``.

    Args:
        name: its name.
        geometry: its body and limits.
        changes: fields to set otherwise (settings files, maze, ...).

    """
    return Robot(
        name=name,
        description=changes.pop("description", "differential-drive robot, body twist genes"),
        parameters=geometry.parameter_specs(),
        settings=changes.pop("settings", SETTINGS),
        commands="evorbc_ros.nodes.twist_commands:TwistCommands",
        command_topics=COMMAND_TOPICS,
        sensors=changes.pop("sensors", "sensors/turtlebot3-burger.yaml"),
        maze=changes.pop("maze", "obstacle"),
        episode_time=changes.pop("episode_time", 120.0),
        footprint_radius=geometry.footprint_radius,
        max_speed=geometry.max_speed,
        family="diff_drive",
        # Its repertoire at Table I's budget is 1.01M primitives of 2 s, about 2M
        # simulated seconds: ~25 generations of 150 genomes x 5 mazes x 120 s, as the 4WS's.
        equal_budget_generations=changes.pop("equal_budget_generations", 25),
        episode_bytes=400,  # the same compiled kernel as the 4WS robots'
        model=geometry,
        **changes,
    )
