"""Where a controller's failed episodes ended (docs/generalisation.md, "Where the hexapod stops").

Reads an `evorbc-evolve evaluate --json` report with its episodes on stdin and writes, as
JSON, every failed episode's end pose (x m, y m, heading rad, maze frame), its straight-line
distance to the target (m), the target's bearing from the robot's heading (deg, counter-
clockwise; beyond +-90 the target is behind the robot), its share of cycles touching a
wall, whether it stalled or fell, and counts: falls, and stalls with the target behind or
ahead.

    .venv/bin/evorbc-evolve evaluate ... --json | .venv/bin/python docs/runs/generalise/failures.py
"""

import json
import math
import sys

from offline_evolution.quality import wrap_angle
from sim_bridge.maze import load_named_maze


def bearing_deg(end: list[float], target: tuple[float, float]) -> float:
    """The target's bearing from a pose ``(x, y, heading rad)``, in (-180, 180] deg."""
    x, y, heading = end
    return math.degrees(float(wrap_angle(math.atan2(target[1] - y, target[0] - x) - heading)))


def main() -> None:
    """Print the failures of the report on stdin."""
    report = json.load(sys.stdin)
    mazes = {}
    rows = []
    for i, e in enumerate(report["episodes"]):
        if e["reached"]:
            continue
        maze = mazes.setdefault(e["maze"], load_named_maze(e["maze"]))
        bearing = bearing_deg(e["end"], maze.target)
        rows.append(
            {
                "episode": i,
                "maze": e["maze"],
                "end": [round(v, 3) for v in e["end"]],
                "final_distance": round(e["final_distance"], 3),
                "target_bearing_deg": round(bearing, 1),
                "contact_share": e["contact_share"],
                "stalled": e["stalled"],
                "fell": e["fell"],
            }
        )
    stalls = [r for r in rows if r["stalled"] and not r["fell"]]
    counts = {
        "episodes": len(report["episodes"]),
        "failed": len(rows),
        "fell": sum(r["fell"] for r in rows),
        "stalled_target_behind": sum(abs(r["target_bearing_deg"]) > 90 for r in stalls),
        "stalled_target_ahead": sum(abs(r["target_bearing_deg"]) <= 90 for r in stalls),
        "neither": sum(not r["fell"] and not r["stalled"] for r in rows),
    }
    json.dump(
        {
            "arbitrator": report["arbitrator"],
            "episode_time": report["episode_time"],
            "counts": counts,
            "failures": rows,
        },
        sys.stdout,
        indent=1,
    )
    print()


if __name__ == "__main__":
    main()
