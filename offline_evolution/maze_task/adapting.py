"""Offline episodes with the onboard controller's adaptation (docs/design/adaptation.md).

:func:`adapting` builds the episode kernel's :class:`~offline_evolution.maze_task.kernel.Adapting`
from a repertoire exactly as :meth:`evorbc_ros.arbitration.Controller.enable_adaptation`
builds its :class:`~evorbc_ros.adaptation.online.OnlineAdaptation`: the same recorded
outcomes, GP inputs, weights and settings arrays, so the kernel, running the same
functions compiled, takes the same observations and chooses the same primitives as the
arbitrator node in a lockstep graph.

What an observation is compared with (``expected``): ``recorded``, the repertoire's
outcomes, which is what the arbitrator node uses; or ``settled``, what each primitive does
once the 4WS model's actuators hold its command
(:func:`sim_bridge.four_ws.steady.settled_outcomes`), which does not mistake the recorded
ramp for damage; for a legged robot, what a whole execution observes when the controller
runs the primitive after others, the gait clock running on, on the intact robot on flat
ground (:func:`sim_bridge.legged.settled.settled_outcomes`).
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.adaptation import AdaptationSettings, outcome_table
from evorbc_ros.adaptation.model import OutcomeModel
from evorbc_ros.adaptation.online import settings_arrays
from evorbc_ros.adaptation.settled import EXPECTED
from evorbc_ros.repertoire import Repertoire
from offline_evolution.maze_task.kernel import Adapting


def expected_outcomes(repertoire: Repertoire, robot, expected: str) -> np.ndarray | None:
    """``(n, 3)`` what each primitive's settled cycles should read, or None (recorded).

    Args:
        robot: a 4WS robot (its ``limits`` and ``commands``), a legged robot's
            :class:`~sim_bridge.legged.settings.LeggedRobotSettings` (a legged task's
            ``robot``) or a simulated legged robot holding them (``settings``).

    Cost of ``settled``: about a second for the shipped 4ws-5 repertoire; for a legged
    one, ``n`` x 4 short PyBullet runs in this process (the shipped hexapod's 405
    primitives: about 20,000 control cycles, half a minute on one free core).

    Raises:
        ValueError: ``settled`` for a robot that is neither 4WS nor legged, or an unknown
            ``expected``.
    """
    if expected not in EXPECTED:
        raise ValueError(f"adaptation expected must be one of {', '.join(EXPECTED)}")
    if expected == "recorded":
        return None
    from sim_bridge.four_ws.motion import MotionLimits
    from sim_bridge.four_ws.steady import settled_outcomes
    from sim_bridge.legged.settings import LeggedRobotSettings

    legged = robot if isinstance(robot, LeggedRobotSettings) else getattr(robot, "settings", None)
    if isinstance(legged, LeggedRobotSettings):
        from evorbc_ros.adaptation.model import LEGGED_SETTINGS
        from sim_bridge.legged import settled

        # The node's legged settings: what its observations skip and sum.
        s = LEGGED_SETTINGS
        return settled.settled_outcomes(
            legged, repertoire.genes, repertoire.eval_time, s.settle_cycles, s.window
        )
    if not isinstance(getattr(robot, "limits", None), MotionLimits):
        raise ValueError(
            f"adaptation expected settled: only for 4WS and legged robots, not {robot.name}"
        )
    return settled_outcomes(robot.commands(repertoire.genes), robot.limits, repertoire.eval_time)


def adapting(
    repertoire: Repertoire,
    settings: AdaptationSettings,
    dt: float,
    expected: np.ndarray | None = None,
) -> Adapting:
    """The kernel's adaptation of an EvoRBC controller of ``repertoire``.

    Args:
        settings: the model's and the settled-cycle rule's.
        dt: s, the robot's control period (the odometry's stamps).
        expected: ``(n, 3)`` (:func:`expected_outcomes`); None: the recorded outcomes.
    """
    recorded = outcome_table(repertoire.behaviour, repertoire.heading)
    model = OutcomeModel(recorded, settings, expected)
    conf, iconf = settings_arrays(model.recorded, repertoire.eval_time, settings)
    return Adapting(
        conf,
        iconf,
        model.features,
        model.recorded,
        np.ascontiguousarray(model.expected),
        np.ascontiguousarray(model.weight, dtype=np.float64),
        float(settings.noise),
        int(settings.capacity),
        int(settings.average),
        float(dt),
    )


def task_adapting(
    task, repertoire: Repertoire, expected: str, robot: str
) -> tuple[AdaptationSettings, object]:
    """The adaptation settings and arrays ``task``'s episodes adapt with (its ``adapt``).

    What ``evaluate --adapt`` and a training run with ``training: adapt: true`` give
    :meth:`~offline_evolution.maze_task.task.MazeTask.adapt`: one code for both. The
    settings are the node's default for ``robot``'s family (legged robots observe whole
    executions); a PyBullet task (``adapting_for``) runs the onboard classes, a kinematic
    one the kernel's :func:`adapting`.

    Args:
        task: a maze task whose episodes adapt (its ``robot`` and control period ``dt``, s).
        expected: ``recorded`` or ``settled`` (:func:`expected_outcomes`).
        robot: the registered robot's name.

    Raises:
        ValueError: ``settled`` for a robot that is not 4WS, or an unknown ``expected``.
    """
    from evorbc_ros.adaptation import settings_for
    from evorbc_ros.arbitration import robot_family

    settings = settings_for(robot_family(robot))
    outcomes = expected_outcomes(repertoire, task.robot, expected)
    if hasattr(task, "adapting_for"):  # PyBullet episodes run the onboard classes
        return settings, task.adapting_for(repertoire, settings, outcomes)
    return settings, adapting(repertoire, settings, task.dt, outcomes)
