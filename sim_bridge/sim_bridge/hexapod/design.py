"""The hexapod's design check for ``evorbc-sim`` (its family's ``design_check``).

The bridge simulates one hexapod design (geometry, servos, physics) and one laser; a
controller evolved for another would run on a robot it was never tried on, so it is
refused in one line naming the first setting that differs (docs/design.md section 11).
"""

from __future__ import annotations

from evorbc_ros.config import ConfigError, config_dir
from evorbc_ros.robots.hexapod import HexapodGeometry
from evorbc_ros.sensors import SensorLayout
from sim_bridge.hexapod.maze_world import DEFAULT_SENSORS
from sim_bridge.hexapod.physics import PhysicsSettings
from sim_bridge.hexapod.robot import describe_simulation
from sim_bridge.robots.design import check_controller_simulation


def check_controller(robot, controller) -> None:
    """Refuse a hexapod controller evolved for another design or laser than the bridge's.

    Args:
        robot: the hexapod's registration.
        controller: the :class:`evorbc_ros.arbitration.Controller` ``evorbc-sim`` runs.

    Raises:
        ConfigError: one line naming the file and the first setting that differs.

    """
    # The bridge simulates the shipped laser; the sensor nodes read its scans with the
    # arbitrator's layout, so another layout would feed the network inputs it never saw.
    laser = SensorLayout.load(config_dir() / DEFAULT_SENSORS)
    if controller.spec.sensors.fingerprint() != laser.fingerprint():
        raise ConfigError(
            f"{controller.arbitrator_path}: its sensor layout differs from the laser the "
            f"bridge simulates (config/{DEFAULT_SENSORS}: 25 beams over +-90 deg, grouped "
            "into 5)"
        )
    check_controller_simulation(
        controller, describe_simulation(HexapodGeometry(), PhysicsSettings())
    )
