"""The motion input from odometry: how far the robot moved over the last window (pure code).

A stuck robot (pressed against a wall, or stopped by a primitive that cannot move it) reads
the same rangefinders and goal inputs cycle after cycle, so a controller without this input
repeats the same choice for ever. Its distance moved over the last ``window`` seconds tells
it (docs/design.md section 5). The radar node computes it from ``nav_msgs/Odometry`` and the
offline legged episodes from the simulated pose with the same code; the compiled 4WS kernel
keeps the same window of past positions (docs/design.md section 5).

Time is the poses' stamps in integer ns, so a lockstep graph (stamps ``k x 0.1 s``) and the
offline episodes compare the same poses exactly.
"""

from __future__ import annotations

import collections

from evorbc_ros.sensors import MotionLayout, motion_reading


class MotionWindow:
    """The poses of the last window and the motion reading of the newest.

    The reading compares the newest position with the newest one stamped at least
    ``window`` earlier, or with the first position seen while less than a window has
    passed. A stamp earlier than the last one (a simulation reset, a restarted
    odometry source) starts the window again, as does :meth:`reset`. A pose stamped as the
    last one replaces it (:attr:`repeated` says so): odometry whose stamps never advance
    reads 0 and keeps one pose, rather than piling up poses for ever.
    """

    def __init__(self, layout: MotionLayout):
        self.layout = layout
        self.window_ns = layout.window_ns
        # (stamp ns, x m, y m), oldest first; the first entry is the reference position.
        self.poses: collections.deque[tuple[int, float, float]] = collections.deque()
        #: True if the last pose had the same stamp as the one before (it replaced it).
        self.repeated = False

    def reset(self) -> None:
        """Forget every pose (a new episode)."""
        self.poses.clear()

    def reading(self, stamp_ns: int, x: float, y: float) -> float:
        """Add the position ``(x, y)`` (m, a fixed frame) at ``stamp_ns``; its reading, 0-1."""
        if self.poses and stamp_ns < self.poses[-1][0]:
            self.poses.clear()
        self.repeated = bool(self.poses) and stamp_ns == self.poses[-1][0]
        if self.repeated:
            self.poses.pop()
        self.poses.append((stamp_ns, x, y))
        # Keep the newest pose at least a window old as the reference, and nothing older.
        cutoff = stamp_ns - self.window_ns
        while len(self.poses) > 1 and self.poses[1][0] <= cutoff:
            self.poses.popleft()
        _, x0, y0 = self.poses[0]
        return motion_reading(x - x0, y - y0, self.layout.distance)
