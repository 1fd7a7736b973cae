"""The simulated world: robot motion models, mazes, sensors and the PyBullet bridge."""
