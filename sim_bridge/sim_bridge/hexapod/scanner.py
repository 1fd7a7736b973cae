"""The hexapod's 2D laser scanner: the legged robot's (:mod:`sim_bridge.legged.scanner`)."""

from sim_bridge.legged.scanner import Scanner

__all__ = ["Scanner"]
