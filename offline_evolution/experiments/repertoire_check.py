"""Check the repertoires against the paper (Sec. IV-D, Fig. 8) for every 4WS robot type.

Generates repertoires at the Table I settings for each robot type and seed, then reports
per type the number of primitives and the mean quality (mean and sd over seeds), the
area and extent of the reachable region, and how symmetric it is. Writes a Markdown
table and a Fig. 8-style picture.

Run: ``python -m offline_evolution.experiments.repertoire_check --seeds 5 --out docs/``
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from evorbc_ros.atomic_io import atomic_write_text
from evorbc_ros.repertoire import Repertoire
from evorbc_ros.robots.four_ws import ROBOT_TYPES
from offline_evolution.repertoire.map_elites import generate_repertoire
from offline_evolution.repertoire.settings import load_settings

ROBOTS = tuple(ROBOT_TYPES)  # the paper's four 4WS types (Fig. 6 and 8)


def occupied_cells(r: Repertoire) -> set[tuple[int, int]]:
    """Grid cells (column, row) that hold a primitive, centred so (0, 0) is the origin."""
    cells = np.rint(r.behaviour / r.bin_size).astype(int)
    return {(int(i), int(j)) for i, j in cells}


def region_figures(r: Repertoire) -> dict[str, float]:
    """Size and symmetry of the region a repertoire covers.

    ``mirror_lr``: share of occupied cells whose left/right mirror (y -> -y) is occupied;
    ``mirror_fb``: the same for the forward/backward mirror (x -> -x).
    """
    cells = occupied_cells(r)
    n = max(1, len(cells))
    x, y = r.behaviour.T
    return {
        "area_m2": len(cells) * r.bin_size**2,
        "mirror_lr": sum((i, -j) in cells for i, j in cells) / n,
        "mirror_fb": sum((-i, j) in cells for i, j in cells) / n,
        "max_forward": float(x.max(initial=0.0)),
        "max_backward": float(-x.min(initial=0.0)),
        "max_sideways": float(np.abs(y).max(initial=0.0)),
    }


def run(seeds: int, out: Path) -> str:
    """Generate every robot x seed, write the table and picture, return the table."""
    rows, examples = [], []
    for robot in ROBOTS:
        stats = []
        for seed in range(1, seeds + 1):
            start = time.perf_counter()
            r = generate_repertoire(load_settings(robot=robot, seed=seed))
            s = r.summary()
            stats.append(
                {
                    "count": s["count"],
                    "mean_quality": s["mean_quality"],
                    "seconds": time.perf_counter() - start,
                    **region_figures(r),
                }
            )
            if seed == 1:
                examples.append(r)
            print(
                f"{robot} seed {seed}: {s['count']} primitives, mean quality "
                f"{s['mean_quality']:.4f}",
                flush=True,
            )
        rows.append((robot, stats))
    table = [
        "| robot | primitives (mean ± sd) | mean quality (mean ± sd) | area (m²) | "
        "left/right mirror | fwd/back mirror | max fwd / back / side (m) | s per run |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for robot, stats in rows:

        def col(key, st=stats):
            return np.array([s[key] for s in st])

        table.append(
            f"| {robot} | {col('count').mean():.1f} ± {col('count').std(ddof=1):.1f} | "
            f"{col('mean_quality').mean():.4f} ± {col('mean_quality').std(ddof=1):.4f} | "
            f"{col('area_m2').mean():.3f} | {col('mirror_lr').mean():.2f} | "
            f"{col('mirror_fb').mean():.2f} | {col('max_forward').mean():.2f} / "
            f"{col('max_backward').mean():.2f} / {col('max_sideways').mean():.2f} | "
            f"{col('seconds').mean():.1f} |"
        )
    text = "\n".join(table) + "\n"
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / "repertoire-check.md", text)
    from offline_evolution.plots.repertoire import plot_repertoire_panels

    plot_repertoire_panels(examples, out / "repertoire-check.png")
    return text


def main() -> None:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--out", type=Path, default=Path("docs"))
    args = parser.parse_args()
    print(run(args.seeds, args.out))


if __name__ == "__main__":
    main()
