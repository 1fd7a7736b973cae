"""Writing a repertoire's settled outcomes for the arbitrator node (``evorbc-evolve settled``).

What each primitive does once its actuators hold its command (a legged robot: what a whole
execution after other primitives does, in PyBullet) is computed with the robot's
simulation, exactly as ``evaluate --adapt-expected settled`` computes it, and written
beside the repertoire for the node, which only reads it (docs/design/adaptation.md, "What
an observation is compared with"; the format: :mod:`evorbc_ros.adaptation.settled`). The
command and the recipes' ``settled`` steps both call :func:`write_settled`.
"""

from __future__ import annotations

from evorbc_ros.adaptation.settled import save_settled
from evorbc_ros.repertoire import Repertoire
from offline_evolution.runs.errors import UserError


def write_settled(repertoire_path: str, out: str) -> Repertoire:
    """Compute the settled outcomes of the repertoire at ``repertoire_path``, write ``out``.

    Returns the repertoire. Takes about a second for the shipped 4ws-5 repertoire, about
    half a minute of one core for the shipped hexapod's (PyBullet, in this process).

    Raises:
        RepertoireError: a bad repertoire file.
        UserError: a repertoire of a robot that is neither 4WS nor legged (one line naming
            the file).
    """
    from offline_evolution.maze_task.adapting import expected_outcomes
    from sim_bridge.robots import make_robot

    repertoire = Repertoire.load(repertoire_path)
    robot = make_robot(repertoire.robot, workers=1)
    try:
        outcomes = expected_outcomes(repertoire, robot, "settled")
    except ValueError as e:
        raise UserError(f"{repertoire_path}: {e}") from None
    finally:
        if hasattr(robot, "close"):  # a PyBullet robot's (unstarted) pool
            robot.close()
    save_settled(out, outcomes, repertoire)
    return repertoire
