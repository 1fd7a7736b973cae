"""The robot-specific half of the simulation bridge: what the families' adapters share.

Each family has its adapter in its own folder: :mod:`sim_bridge.four_ws.bridge`,
:mod:`sim_bridge.diff_drive.bridge` (both :class:`KinematicBridge`),
:mod:`sim_bridge.hexapod.bridge` and :mod:`sim_bridge.legged.bridge` (both
:class:`~sim_bridge.legged.bridge.TrajectoryBridge`). Each adapter owns its simulated
world, subscribes its command topics, fills the joint states and laser scan, and steps the
world with the commands of the cycle. The bridge node (:mod:`sim_bridge.bridge_node`) runs
the loop, clock, odometry and result the same way for every robot, and finds a robot's
adapter by its family (:func:`bridge_robot_class`, :mod:`sim_bridge.robots.adapters`;
docs/your-robot.md gives the adapter's interface).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from evorbc_ros.nodes.common import StartupError, robot_named
from evorbc_ros.robots.registry import RobotError
from sim_bridge.geometry import planar_quaternion
from sim_bridge.perturbation import WorldDraw
from sim_bridge.robots.adapters import bridge_class
from sim_bridge.world import LaserConfig


@dataclass(frozen=True)
class ScanGeometry:
    """What a LaserScan message says about the beams (rad, m)."""

    angle_min: float
    angle_max: float
    angle_increment: float
    range_min: float
    range_max: float


class KinematicBridge:
    """What the kinematic robots' adapters share: the laser, the scan and a planar pose."""

    def _laser(self, node) -> LaserConfig:
        """The simulated scanner from the node's parameters; sets :attr:`scan_geometry`."""
        laser = LaserConfig(beams=node.params["laser_beams"], range_max=node.params["laser_range"])
        self.scan_geometry = ScanGeometry(
            laser.angle_min,
            laser.angle_min + laser.increment * (laser.beams - 1),
            laser.increment,
            laser.range_min,
            laser.range_max,
        )
        return laser

    def scan(self) -> np.ndarray:
        """Laser ranges (m)."""
        return self.world.scan()

    def perturb(self, draw: WorldDraw) -> tuple[str, ...]:
        """Apply row 0 of a perturbation set's ``draw``; the quantities applied.

        The kinematic world takes the wheel speed gain and a 4WS robot's damaged wheel
        (docs/perturbations.md); the rest of a set is the offline episodes' alone.
        """
        self.world.speed_gain = float(draw.values["wheel_speed_gain"][0])
        applied = ["wheel_speed_gain"]
        if draw.damage is not None and draw.damage.spec.family == "four_ws":
            self.world.damage = draw.kernel_arrays(1.0)[0, 4:7].copy()
            self.world.damage_key = int(draw.keys[0])
            applied.append(draw.damage.spec.kind)
        return tuple(applied)

    def body_pose(self) -> tuple[tuple, tuple]:
        """Position (m) and orientation (xyzw) of ``base_link`` in ``odom``: planar."""
        x, y, h = self.world.pose
        return (x, y, 0.0), (0.0, 0.0, *planar_quaternion(h))


def bridge_robot_class(robot: str) -> type:
    """The bridge adapter class of ``robot``'s family (:mod:`sim_bridge.robots.adapters`).

    Raises:
        StartupError: an unknown robot (listing the known ones), or an adapter that cannot
            be imported.
    """
    try:
        return bridge_class(robot_named(robot))
    except RobotError as e:
        raise StartupError(str(e)) from None
