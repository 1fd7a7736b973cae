"""The ROS 2 nodes of evorbc (thin adapters over the pure code in evorbc_ros)."""
