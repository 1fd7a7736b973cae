"""The hexapod in PyBullet: URDF, physics, primitive evaluation and worker pools."""
