"""Online correction: odometry poses and the primitives chosen -> observations (pure code).

Each control cycle the controller hands in the newest odometry pose, then chooses. The
motion between the poses of two successive choices is what the primitive chosen at the
first did for that cycle. It is an observation only once the primitive has run
``settle_cycles`` cycles before it: the 4WS robot's actuators move at most 0.04 m/s and
9 deg per 0.1 s cycle, so a primitive's first cycles depend on the one before
(docs/design.md section 24). Settled cycles of one primitive are summed (up to
``window``), extended to the repertoire's evaluation time as an arc, and given to the
:class:`~evorbc_ros.adaptation.model.OutcomeModel`.

The rule's state and steps are arrays and plain functions (:mod:`.cycles`), which the
offline episode kernel compiles: this class is a thin wrapper over them.

Poses carry their stamps (integer ns), so an observation's duration is the odometry's
own, as in the motion input; a stamp that does not advance breaks the run of cycles.
"""

from __future__ import annotations

import numpy as np

from evorbc_ros.adaptation import cycles
from evorbc_ros.adaptation.model import AdaptationSettings, OutcomeModel


class OnlineAdaptation:
    """An :class:`OutcomeModel` fed by poses and choices.

    Args:
        recorded, expected: as :class:`OutcomeModel`'s.
        horizon: the repertoire's evaluation time ``T`` (s).
        settings: :class:`AdaptationSettings`.
        functions: :func:`cycles.plain` (default) or :func:`cycles.compiled`: the same bits.
    """

    def __init__(
        self,
        recorded: np.ndarray,
        horizon: float,
        settings: AdaptationSettings | None = None,
        expected: np.ndarray | None = None,
        functions: dict | None = None,
    ):
        self.settings = settings or AdaptationSettings()
        self.fn = functions or cycles.plain()
        self.model = OutcomeModel(recorded, self.settings, expected, self.fn)
        self.horizon = horizon
        self.conf, self.iconf = settings_arrays(self.model.recorded, horizon, self.settings)
        #: m and rad over T: how far a cycle's extended motion may be from the last one's.
        self.tolerance = (float(self.conf[cycles.POS_TOL]), float(self.conf[cycles.HEAD_TOL]))
        self.ints, self.floats = cycles.new_state()
        self.reset()

    def reset(self) -> None:
        """Forget every observation and the current execution."""
        self.model.reset()
        self.ints[:], self.floats[:] = cycles.new_state()

    def _model(self) -> tuple:
        return (*self.model.arrays(), self.settings.noise)

    def put_pose(self, stamp_ns: int, x: float, y: float, yaw: float) -> None:
        """The newest odometry pose (m, m, rad in its fixed frame) at ``stamp_ns``."""
        self.fn["put_pose"](self.ints, self.floats, int(stamp_ns), float(x), float(y), float(yaw))

    def before_choice(self) -> None:
        """Attribute the motion since the last choice to the primitive chosen then."""
        self.fn["before_choice"](self.ints, self.floats, self.conf, self.iconf, *self._model())

    def after_choice(self, index: int) -> None:
        """The primitive chosen now (``-1``: none, the robot stops)."""
        self.fn["after_choice"](self.ints, self.floats, self.conf, int(index), *self._model())

    def choose(self, x: float, y: float, looked_up: int) -> int:
        """The primitive to run, given the lookup grid's answer ``looked_up``.

        ``looked_up`` stands while there is no observation (so an adapting controller
        starts exactly as the evolved one). The controller passes ``(x, y)``, the centre of
        the grid cell of the mapping's point, where the grid holds the brute-force nearest:
        where no primitive is corrected, the answer is the grid's (:func:`cycles.choose`).
        """
        m = self.model
        return int(
            self.fn["choose"](
                self.iconf, float(x), float(y), int(looked_up), m.recorded, m.corrected,
                m.counts, m.weight,
            )
        )  # fmt: skip


def adapted_choice(adaptation: OnlineAdaptation, lookup, index: int, x: float, y: float) -> int:
    """One control cycle of an adapting EvoRBC controller: the primitive to run.

    Attributes the motion since the last choice to the primitive chosen then, matches the
    grid's choice ``index`` (``-1``: none) given at the centre of the grid cell of the
    mapping's point ``(x, y)`` (m), where the grid holds the brute-force nearest, so that
    with no correction either rule chooses as the grid, bit for bit (docs/design.md section
    24), and records the choice. :meth:`evorbc_ros.arbitration.Controller.step` and the
    legged robots' offline episodes both call it (docs/design/adaptation.md).

    Args:
        lookup: the controller's :class:`~evorbc_ros.mapping.PrimitiveLookup`.
    """
    adaptation.before_choice()
    if index >= 0:
        index = adaptation.choose(*lookup.cell_centre(x, y), index)
    adaptation.after_choice(index)
    return index


def settings_arrays(
    recorded: np.ndarray, horizon: float, settings: AdaptationSettings
) -> tuple[np.ndarray, np.ndarray]:
    """``(conf, iconf)`` of :mod:`.cycles` for a repertoire's ``(n, 3)`` recorded outcomes.

    The tolerances are ``steady_tolerance`` times the larger of the ``dx``, ``dy`` extents
    (m over ``T``) and times the heading extent (rad over ``T``).
    """
    extent = recorded.max(axis=0) - recorded.min(axis=0)
    tol = settings.steady_tolerance
    conf = np.array(
        [
            tol * float(max(extent[0], extent[1])),
            tol * float(extent[2]),
            horizon,
            float(settings.min_cycles),
        ]
    )
    match = cycles.MATCH_OUTCOME if settings.match == "outcome" else cycles.MATCH_POINT
    steady = cycles.STEADY_AGREE if settings.steady == "agree" else cycles.STEADY_HELD
    iconf = np.array([settings.settle_cycles, settings.window, match, steady], dtype=np.int64)
    return conf, iconf
