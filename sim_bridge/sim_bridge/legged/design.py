"""A legged robot's design check for ``evorbc-sim`` (the ``legged`` family's ``design_check``).

The bridge simulates the design the robot's settings file describes (URDF, gait, servos,
physics) with the laser of its registration's sensor layout; a controller evolved for
another would run on a robot it was never tried on, so it is refused in one line naming
the first setting that differs (docs/design.md section 11), as the hexapod's is.
"""

from __future__ import annotations

from evorbc_ros.sensors import SensorLayout
from sim_bridge.legged.settings import load_robot_settings
from sim_bridge.robots.design import check_controller_laser, check_controller_simulation


def check_controller(robot, controller) -> None:
    """Refuse a controller evolved for another design or laser than the bridge's.

    Args:
        robot: the legged robot's registration.
        controller: the :class:`evorbc_ros.arbitration.Controller` ``evorbc-sim`` runs.

    Raises:
        ConfigError: one line naming the file and the first setting that differs.

    """
    laser_file = robot.sensors_file()
    check_controller_laser(controller, SensorLayout.load(laser_file), laser_file, robot.name)
    check_controller_simulation(controller, load_robot_settings(robot.model.path()).describe())
