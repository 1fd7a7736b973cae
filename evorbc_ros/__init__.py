"""EvoRBC onboard control: robot definitions, repertoires, arbitrators and ROS 2 nodes.

Everything in this package runs on the robot and needs numpy and pyyaml only (plus rclpy
for the nodes).
"""
