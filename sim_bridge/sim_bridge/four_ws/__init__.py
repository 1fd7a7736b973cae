"""The 4WS robots' simulation: motion model, search robot, bridge world and adapter.

The simulation half of :mod:`evorbc_ros.robots.four_ws` (docs/design.md sections 2 and 19).
"""
