"""How an episode's outcome is said, in one phrase, by every program that reports one.

``evorbc-sim`` (an episode through the ROS 2 graph) and ``evorbc-evolve replay`` (the same
controller offline) describe an episode with the same words and numbers, so that a fall,
a miss or an arrival reads alike in both ("fell over after 11.7 s (3.20 m left)").

This module depends on the standard library only: the offline tools import it without ROS.
"""

from __future__ import annotations


def episode_verdict(result: dict) -> str:
    """One phrase for an episode: reached, fell over, interrupted, or where time ran out.

    Args:
        result: ``reached`` (bool), ``time`` (s: to the target, the fall, the interruption
            or the end of the episode), ``final_distance`` (m to the target), and
            optionally ``fell`` and ``interrupted`` (bool), as the bridge's result file
            and ``replay --json`` hold them.
    """
    if result["reached"]:
        return f"reached the target in {result['time']:.1f} s"
    left = f"{result['final_distance']:.2f} m left"
    if result.get("fell"):
        return f"fell over after {result['time']:.1f} s ({left})"
    if result.get("interrupted"):
        return f"interrupted after {result['time']:.1f} s ({left})"
    return f"did not reach the target ({left} after {result['time']:.1f} s)"


def episode_line(maze: str, result: dict) -> str:
    """``MAZE: VERDICT, fitness F`` (eq. 5; no fitness for an interrupted episode)."""
    fitness = "" if result.get("interrupted") else f", fitness {result['fitness']:.3f}"
    return f"{maze}: {episode_verdict(result)}{fitness}"
