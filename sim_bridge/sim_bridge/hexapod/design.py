"""The hexapod's design check for ``evorbc-sim`` (its family's ``design_check``).

The bridge simulates one hexapod design (geometry, servos, physics) and one laser; a
controller evolved for another would run on a robot it was never tried on, so it is
refused in one line naming the first setting that differs (docs/design.md section 11).
"""

from __future__ import annotations

from evorbc_ros.config import config_dir
from evorbc_ros.robots.hexapod import HexapodGeometry
from evorbc_ros.sensors import SensorLayout
from sim_bridge.hexapod.maze_world import DEFAULT_SENSORS
from sim_bridge.hexapod.physics import PhysicsSettings
from sim_bridge.hexapod.robot import describe_simulation
from sim_bridge.robots.design import check_controller_laser, check_controller_simulation


def check_controller(robot, controller) -> None:
    """Refuse a hexapod controller evolved for another design or laser than the bridge's.

    Args:
        robot: the hexapod's registration.
        controller: the :class:`evorbc_ros.arbitration.Controller` ``evorbc-sim`` runs.

    Raises:
        ConfigError: one line naming the file and the first setting that differs.

    """
    # The bridge simulates the shipped laser (25 beams over +-90 deg, grouped into 5).
    laser = SensorLayout.load(config_dir() / DEFAULT_SENSORS)
    check_controller_laser(controller, laser, f"config/{DEFAULT_SENSORS}", robot.name)
    check_controller_simulation(
        controller, describe_simulation(HexapodGeometry(), PhysicsSettings())
    )
