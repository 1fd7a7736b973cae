"""A simulated robot's design as files record it, and the check that refuses another.

A robot simulated with physics (the hexapod) describes its design as plain data: its
geometry, servos and physics settings (``describe()`` of its task and simulated robot).
Repertoires, checkpoints and arbitrator files record it, so that a file made for another
design is refused with the first setting that differs rather than reused (docs/design.md
section 11). A kinematic robot (4WS) records none, and nothing is compared.
"""

from __future__ import annotations

from evorbc_ros.config import ConfigError
from evorbc_ros.json_files import first_difference
from evorbc_ros.repertoire import Repertoire, RepertoireError
from evorbc_ros.sensors import SensorLayout


def simulation_mismatch(recorded: dict | None, simulation: dict | None, where: str) -> str | None:
    """The first setting in which a file's ``recorded`` simulation differs from ``simulation``.

    A file that records none (made by hand, or for the 4WS kinematics) passes: there is
    nothing to compare.
    """
    if recorded is None:
        return None
    return first_difference({"simulation": recorded}, {"simulation": simulation}, where)


def check_simulation(
    repertoire: Repertoire, simulation: dict | None, source: str = "the repertoire"
) -> None:
    """Refuse a repertoire evolved for another simulated robot than ``simulation``.

    Raises:
        RepertoireError: one line naming ``source`` and the first setting that differs.

    """
    mismatch = simulation_mismatch(
        repertoire.algorithm.get("simulation"), simulation, "the repertoire"
    )
    if mismatch:
        raise RepertoireError(f"{source}: was evolved for a different robot ({mismatch})")


def check_controller_laser(controller, laser: SensorLayout, laser_file, robot: str) -> None:
    """Refuse a controller whose sensor layout is not the laser the bridge simulates.

    The sensor nodes read the bridge's scans with the arbitrator's layout, so another
    layout would feed the network inputs it never saw.

    Raises:
        ConfigError: one line naming the arbitrator file, the laser's file and the first
            setting that differs (the controller's value, then the laser's).

    """
    what = laser.difference(controller.spec.sensors, "the controller")
    if what:
        raise ConfigError(
            f"{controller.arbitrator_path}: its sensor layout differs from the laser the "
            f"bridge simulates for {robot} ({laser_file}: {what})"
        )


def check_controller_simulation(controller, simulation: dict) -> None:
    """Refuse a controller whose repertoire or arbitrator was evolved for another design.

    Args:
        controller: the :class:`evorbc_ros.arbitration.Controller` ``evorbc-sim`` runs.
        simulation: the design the bridge simulates (``describe()``).

    Raises:
        RepertoireError, ConfigError: one line naming the file and the first setting that
            differs.

    """
    if controller.repertoire is not None:
        check_simulation(controller.repertoire, simulation, controller.repertoire_path)
    recorded = controller.spec.evolution.get("simulation")
    mismatch = simulation_mismatch(recorded, simulation, "the controller")
    if mismatch:
        raise ConfigError(
            f"{controller.arbitrator_path}: was evolved for a different robot ({mismatch})"
        )
