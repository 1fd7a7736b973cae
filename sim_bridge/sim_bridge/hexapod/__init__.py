"""The hexapod's simulation: URDF, physics, search robot, maze world, bridge adapter, design check.

The simulation half of :mod:`evorbc_ros.robots.hexapod`, built on the legged robots' code
(:mod:`sim_bridge.legged`).
"""
