"""Online correction: odometry poses and the primitives chosen -> observations (pure code).

Each control cycle the controller hands in the newest odometry pose, then chooses. The
motion between the poses of two successive choices is what the primitive chosen at the
first did for that cycle. It is an observation only once the primitive has run
``settle_cycles`` cycles before it: the 4WS robot's actuators move at most 0.04 m/s and
9 deg per 0.1 s cycle, so a primitive's first cycles depend on the one before
(docs/design.md section 24). Settled cycles of one primitive are summed (up to
``window``), extended to the repertoire's evaluation time as an arc, and given to the
:class:`~evorbc_ros.adaptation.model.OutcomeModel`.

Poses carry their stamps (integer ns), so an observation's duration is the odometry's
own, as in the motion input; a stamp that does not advance breaks the run of cycles.
"""

from __future__ import annotations

import math

import numpy as np

from evorbc_ros.adaptation.model import AdaptationSettings, OutcomeModel
from evorbc_ros.adaptation.motion import compose, extend_arc, relative_motion


class OnlineAdaptation:
    """An :class:`OutcomeModel` fed by poses and choices.

    Args:
        recorded, expected: as :class:`OutcomeModel`'s.
        horizon: the repertoire's evaluation time ``T`` (s).
        settings: :class:`AdaptationSettings`.
    """

    def __init__(
        self,
        recorded: np.ndarray,
        horizon: float,
        settings: AdaptationSettings | None = None,
        expected: np.ndarray | None = None,
    ):
        self.settings = settings or AdaptationSettings()
        self.model = OutcomeModel(recorded, self.settings, expected)
        self.horizon = horizon
        extent = self.model.recorded.max(axis=0) - self.model.recorded.min(axis=0)
        tol = self.settings.steady_tolerance
        #: m and rad over T: how far a cycle's extended motion may be from the last one's.
        self.tolerance = (tol * float(max(extent[0], extent[1])), tol * float(extent[2]))
        self.reset()

    def reset(self) -> None:
        """Forget every observation and the current execution."""
        self.model.reset()
        self.pose: tuple[int, float, float, float] | None = None  # newest (stamp ns, x, y, yaw)
        self._clear_run()

    def _clear_run(self) -> None:
        self.running = -1  # the primitive chosen at the last choice (-1: none)
        self.held = 0  # consecutive choices of it, the last included
        self.anchor: tuple[int, float, float, float] | None = None  # pose at the last choice
        self.last: tuple[float, float, float] | None = None  # last cycle's motion over T
        self._clear_sum()

    def _clear_sum(self) -> None:
        self.summed = (0.0, 0.0, 0.0)  # settled motion so far, in its first pose's frame
        self.summed_ns = 0
        self.summed_cycles = 0

    def put_pose(self, stamp_ns: int, x: float, y: float, yaw: float) -> None:
        """The newest odometry pose (m, m, rad in its fixed frame) at ``stamp_ns``."""
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            return
        self.pose = (int(stamp_ns), float(x), float(y), float(yaw))

    def before_choice(self) -> None:
        """Attribute the motion since the last choice to the primitive chosen then."""
        pose, anchor = self.pose, self.anchor
        if anchor is None or pose is None or pose[0] <= anchor[0]:
            # No odometry, or none newer: the cycle cannot be measured; start again.
            self._flush()
            self._clear_run()
            return
        step = relative_motion(anchor[1], anchor[2], anchor[3], pose[1], pose[2], pose[3])
        seen = extend_arc(*step, (pose[0] - anchor[0]) * 1e-9, self.horizon)
        last, self.last = self.last, seen
        if (
            self.held > self.settings.settle_cycles
            and last is not None
            and self._steady(last, seen)
        ):
            self.summed = compose(*self.summed, *step)
            self.summed_ns += pose[0] - anchor[0]
            self.summed_cycles += 1
            if self.summed_cycles >= self.settings.window:
                self._flush()
        else:
            self._flush()  # what was summed is settled; this cycle is not

    def _steady(self, a: tuple, b: tuple) -> bool:
        """Whether cycle ``b`` translated and agrees with cycle ``a`` within the tolerance.

        Two cycles without translation agree, but tell nothing: wheels that fight while
        they turn towards a command stop the 4WS body for a cycle or two, and a wall keeps
        the position (every 4WS primitive that moves translates).
        """
        pos, head = self.tolerance
        return (
            math.hypot(b[0], b[1]) > pos
            and math.hypot(a[0] - b[0], a[1] - b[1]) <= pos
            and abs(a[2] - b[2]) <= head
        )

    def after_choice(self, index: int) -> None:
        """The primitive chosen now (``-1``: none, the robot stops)."""
        if index != self.running:
            self._flush()
            self.running = index
            self.held = 0
            self.last = None
        self.held = self.held + 1 if index >= 0 else 0
        self.anchor = self.pose

    def _flush(self) -> None:
        """Give the summed settled motion, if any, to the model."""
        if self.summed_cycles and self.running >= 0:
            outcome = extend_arc(*self.summed, self.summed_ns * 1e-9, self.horizon)
            self.model.observe(self.running, np.array(outcome))
        self._clear_sum()

    def choose(self, x: float, y: float, looked_up: int) -> int:
        """The primitive whose corrected ``(dx, dy)`` is nearest the point ``(x, y)`` (m).

        ``looked_up`` is the repertoire's lookup-grid answer, which stands while there is
        no observation (so an adapting controller starts exactly as the evolved one). The
        controller passes the centre of the grid cell of the mapping's point, where the
        grid holds the brute-force nearest: where no primitive is corrected, the answer
        is the grid's.
        """
        if self.model.used == 0 or looked_up < 0:
            return looked_up
        if self.settings.match == "outcome":
            return self.model.nearest_outcome(looked_up)
        return self.model.nearest(x, y)
