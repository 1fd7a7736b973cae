"""Differential-drive robots' simulation: motion model, search robot, bridge world and adapter.

The simulation half of :mod:`evorbc_ros.robots.diff_drive` (docs/design.md section 19).
"""
