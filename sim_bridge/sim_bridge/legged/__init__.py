"""Legged robots in PyBullet from a URDF plus a settings file (docs/legged.md)."""
