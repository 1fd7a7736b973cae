"""The repertoire and legged settings the legged benches read, or one line saying why not.

Used by bench/legged_hold.py, legged_switching.py and legged_transitions.py.

These benches drive the settings-file legged robots' PyBullet simulation
(``sim_bridge.legged``: the A1, the Laikago, robots from a URDF). A repertoire of another
robot (the hexapod, a 4WS robot) has no such model, and is refused in one line rather
than failing on a missing attribute.
"""

from __future__ import annotations

import sys

from evorbc_ros.repertoire import Repertoire


def load_legged(repertoire: str, settings: str | None = None):
    """``(Repertoire, LeggedRobotSettings)`` of ``repertoire``.

    Exits (status 1) with one line if the file cannot be read or its robot is not a
    settings-file legged robot.

    ``settings``: the legged settings file to simulate (default: the registered robot's
    model file; a recipe's robot needs its folder on ``$EVORBC_ROBOT_PATH``).
    """
    from evorbc_ros.config import ConfigError
    from evorbc_ros.robots.registry import lookup
    from sim_bridge.legged.settings import LeggedRobotSettings, load_robot_settings

    try:
        rep = Repertoire.load(repertoire)
        if settings is None:
            model = lookup(rep.robot).model
            path = getattr(model, "path", None)
            if path is None:
                sys.exit(
                    f"{sys.argv[0]}: error: {repertoire}: robot {rep.robot} is not a "
                    "settings-file legged robot (sim_bridge.legged); give --settings or a "
                    "repertoire of one (the A1, a robot from a URDF)"
                )
            settings = path()
        loaded = load_robot_settings(settings)
    except (ConfigError, KeyError, OSError, ValueError) as e:
        sys.exit(f"{sys.argv[0]}: error: {e}")
    if not isinstance(loaded, LeggedRobotSettings):
        sys.exit(f"{sys.argv[0]}: error: {settings}: not a legged robot's settings")
    return rep, loaded
