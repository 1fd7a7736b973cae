"""The four four-wheel-steering robots of the paper's Fig. 6, registered.

:func:`four_ws_robot` is also the building block for a 4WS variant in a package of its
own: give it a :class:`~evorbc_ros.robots.four_ws.FourWSType` (which genes drive which
wheel commands) and it fills in everything else from the 4WS robots' simulation, task,
bridge adapters (family ``four_ws``), commands, settings and defaults
(docs/your-robot.md).
"""

from __future__ import annotations

import dataclasses

from evorbc_ros.robots.four_ws import ROBOT_TYPES, FourWSType
from evorbc_ros.robots.record import Robot, SettingsFiles

#: Topics the 4WS command interface publishes: ros2_control forward command controllers.
COMMAND_TOPICS = ("steering_position_controller/commands", "wheel_velocity_controller/commands")
#: Shared by every 4WS robot: paper Table I for 4-wheeled robots.
SETTINGS = SettingsFiles(
    repertoire="repertoire/4ws.yaml",
    arbitrator="arbitrator/4ws.yaml",
    neat="neat/4ws.ini",
    task="tasks/maze-4ws.yaml",
)

DESCRIPTIONS = {
    "2ws-2": "4WS body, front wheels steered together, rear wheels fixed",
    "2ws-3": "4WS body, front wheels steered independently, rear wheels fixed",
    "4ws-3": "4WS body, front pair and rear pair each steered together",
    "4ws-5": "4WS body, all four wheels steered independently",
}


def four_ws_robot(robot_type: FourWSType, description: str = "", **changes) -> Robot:
    """The registration of a 4WS robot type (docs/design.md section 2).

    Args:
        robot_type: its genes and how they drive the five wheel commands, on its body
            (``robot_type.geometry``, the paper's if None); its name is the robot's name.
        description: one line for listings (default: the gene names).
        changes: fields to set otherwise (settings files, maze, shipped controller, ...).

    """
    geometry = robot_type.body()
    robot = Robot(
        name=robot_type.name,
        description=description or f"4WS robot with genes {', '.join(robot_type.parameter_names)}",
        parameters=robot_type.parameter_specs(geometry),
        settings=SETTINGS,
        commands="evorbc_ros.nodes.wheel_commands:WheelCommands",
        command_topics=COMMAND_TOPICS,
        sensors="sensors/4ws.yaml",
        maze="obstacle",
        episode_time=120.0,  # s, paper Table I
        footprint_radius=geometry.footprint_radius,
        max_speed=geometry.max_speed,
        family="four_ws",
        # The 4WS repertoire costs about 2M simulated seconds: 25 generations of
        # 150 genomes x 5 mazes x 120 s (paper Sec. IV-C).
        equal_budget_generations=25,
        # Measured: the compiled kernel keeps about 350 bytes per episode of a generation
        # (docs/performance.md), rounded up.
        episode_bytes=400,
        model=robot_type,
        node_defaults=(("wheel_radius", geometry.wheel_radius),),
    )
    return dataclasses.replace(robot, **changes) if changes else robot


#: The controller shipped in ``evorbc_ros/data`` (its README says how it was made).
SHIPPED = {
    "4ws-5": {
        "shipped_repertoire": "4ws-5.repertoire.json",
        "shipped_arbitrator": "4ws-5.arbitrator.json",
        # Trained on the paper's five mazes only (paper Table I); the shipped one also on
        # generated mazes (evorbc_ros/data/README.md, docs/generalisation.md).
        "paper_arbitrator": "4ws-5-paper.arbitrator.json",
    }
}

ROBOTS = tuple(
    four_ws_robot(t, DESCRIPTIONS[name], **SHIPPED.get(name, {})) for name, t in ROBOT_TYPES.items()
)
