"""Clearance-aware path search on a rasterised maze (docs/design.md sections 4 and 21).

Is a maze solvable for a robot, how long is the way, how narrow are its gaps.

The maze generator (:mod:`offline_evolution.mazes.generator`) proves each maze it makes
solvable with it, the held-out evaluation measures progress along it, and the shipped mazes'
tests (``tests/test_mazes.py``) hold them to it.

The maze is sampled on a square grid of cell centres over ``Maze.bounds()``. A cell is free when its
centre is at least ``margin`` m from every wall surface, so a robot of radius 0.05 m (the defaults
are the 4WS robot's) moving between free cells keeps ``margin - 0.05`` m of slack. Distances to the
target are geodesic over the free cells with 8-connectivity (steps of ``cell`` and ``cell *
sqrt(2)`` m), an upper bound on the true shortest length (by at most 8 %); :func:`taut_path` pulls
the grid path straight to measure the length and the turns of the path a planner would take.

Run ``python -m offline_evolution.mazes.paths`` to print the figures of every shipped maze.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.ndimage import binary_dilation
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from sim_bridge.maze import Maze

# The pure clearance and gap searches live with the fitting, which the bridge uses too.
from sim_bridge.maze_fit import clearance_grid, narrowest_gap

ROBOT_RADIUS = 0.05  # m, collision footprint of the 4WS robot (docs/design.md section 2)
MARGIN = 0.06  # m, clearance a path must keep from every wall surface
SNAP = 0.02  # m, a start may step this far to the nearest free cell (clearance 0.05 -> 0.06)
FOLLOW = 0.08  # m, distance a wall follower keeps from the wall it follows


@dataclass(frozen=True)
class Field:
    """Free cells of a maze and the geodesic distance from each to the target."""

    xs: np.ndarray  # (nx,) cell-centre x, m
    ys: np.ndarray  # (ny,) cell-centre y, m
    clearance: np.ndarray  # (ny, nx) distance from the cell centre to the nearest wall, m
    free: np.ndarray  # (ny, nx) bool
    distance: np.ndarray  # (ny, nx) geodesic distance to the target region, m (inf: cut off)
    towards: np.ndarray  # (ny, nx) flat index of the next cell towards the target (-1: none)
    snap: float = SNAP  # m, how far a point may step to the nearest free cell

    @cached_property
    def snapped(self) -> np.ndarray:
        """See :func:`snapped_distance`."""
        from scipy.ndimage import grey_erosion

        free_distance = np.where(self.free, self.distance, np.inf)
        return grey_erosion(free_distance, footprint=_snap_disc(self))

    def to_go(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Shortest path lengths (m) to the target from points ``(k,)`` (x, y in m).

        Each point takes the cell it lies in and the best free cell within ``snap`` of it
        (a robot may sit closer to a wall than the margin); inf where there is none. Cheap
        for whole traces; :meth:`distance_from` measures one point exactly.
        """
        best = self.snapped
        cell = self.xs[1] - self.xs[0]
        i = np.rint((np.asarray(x) - self.xs[0]) / cell).astype(int)
        j = np.rint((np.asarray(y) - self.ys[0]) / cell).astype(int)
        i, j = np.clip(i, 0, len(self.xs) - 1), np.clip(j, 0, len(self.ys) - 1)
        return best[j, i]

    def distance_from(self, x: float, y: float) -> float:
        """Shortest path length (m) from ``(x, y)`` to the target; inf if there is none."""
        gx, gy = np.meshgrid(self.xs, self.ys)
        step = np.hypot(gx - x, gy - y)
        near = (step <= self.snap) & self.free
        if not near.any():
            return math.inf
        return float((self.distance[near] + step[near]).min())

    def grid_path(self, x: float, y: float) -> np.ndarray:
        """``(k, 2)`` cell centres of the shortest path from ``(x, y)`` to the target."""
        gx, gy = np.meshgrid(self.xs, self.ys)
        cost = np.where(self.free, self.distance + np.hypot(gx - x, gy - y), np.inf)
        cost[np.hypot(gx - x, gy - y) > self.snap] = np.inf
        node = int(np.argmin(cost))
        if not math.isfinite(cost.flat[node]):
            raise ValueError(f"no path from ({x}, {y})")
        nodes = [node]
        while self.towards.flat[nodes[-1]] >= 0:
            nodes.append(int(self.towards.flat[nodes[-1]]))
        j, i = np.unravel_index(np.array(nodes), self.free.shape)
        return np.column_stack([self.xs[i], self.ys[j]])


@dataclass(frozen=True)
class DistanceGrid:
    """Shortest path length to the target from anywhere in a maze, on a grid (float32).

    Built by :func:`distance_grid` from a :class:`Field`: a free cell (or one within ``snap``
    of one) holds its geodesic distance; any other cell (a robot pressed into a corner
    narrower than the margin) the distance of the nearest such cell plus the straight step
    to it, so every point of the maze has a finite, continuous-enough value. Cells cut off
    from the target (an enclosed pocket) hold the nearest reachable cell's value too.
    """

    x0: float  # m, x of cell column 0's centre
    y0: float  # m, y of cell row 0's centre
    cell: float  # m, grid cell side
    values: np.ndarray  # (ny, nx) float32, m

    def at(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Path lengths (m, float64) to the target from points ``x, y (k,)`` in m."""
        ny, nx = self.values.shape
        i = np.clip(np.rint((np.asarray(x) - self.x0) / self.cell).astype(np.int64), 0, nx - 1)
        j = np.clip(np.rint((np.asarray(y) - self.y0) / self.cell).astype(np.int64), 0, ny - 1)
        return self.values[j, i].astype(np.float64)


def distance_grid(field: Field) -> DistanceGrid:
    """The :class:`DistanceGrid` of ``field`` (its :meth:`Field.to_go`, completed)."""
    from scipy.ndimage import distance_transform_edt

    values = field.snapped
    known = np.isfinite(values)
    cell = float(field.xs[1] - field.xs[0])
    if not known.any():
        raise ValueError("the target cannot be reached from any cell")
    if not known.all():
        step, (jj, ii) = distance_transform_edt(~known, return_indices=True)
        values = values[jj, ii] + step * cell
    return DistanceGrid(float(field.xs[0]), float(field.ys[0]), cell, values.astype(np.float32))


def solve(maze: Maze, cell: float = 0.01, margin: float = MARGIN, snap: float = SNAP) -> Field:
    """Free cells of ``maze`` and their geodesic distances to the target region.

    Args:
        cell: grid cell side, m.
        margin: m, the clearance a free cell keeps from every wall surface (the robot's
            footprint radius plus some slack).
        snap: m, how far a start may step to the nearest free cell (see
            :meth:`Field.distance_from`); the 4WS robot's starts keep its 0.05 m radius clear,
            so 0.02 m takes them to the 0.06 m margin.
    """
    xs, ys, clear = clearance_grid(maze, cell)
    ny, nx = clear.shape
    free = clear >= margin
    index = np.arange(ny * nx).reshape(ny, nx)
    rows, cols, weights = [], [], []
    # Half of the 8 neighbours; the graph is undirected so the others come for free.
    for dj, di, w in (
        (0, 1, cell),
        (1, 0, cell),
        (1, 1, cell * math.sqrt(2)),
        (1, -1, cell * math.sqrt(2)),
    ):
        a = free[: ny - dj, max(0, -di) : nx - max(0, di)]
        b = free[dj:, max(0, di) : nx - max(0, -di)]
        both = a & b
        rows.append(index[: ny - dj, max(0, -di) : nx - max(0, di)][both])
        cols.append(index[dj:, max(0, di) : nx - max(0, -di)][both])
        weights.append(np.full(int(both.sum()), w))
    graph = coo_matrix(
        (np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))),
        shape=(ny * nx, ny * nx),
    ).tocsr()
    gx, gy = np.meshgrid(xs, ys)
    goal = free & (np.hypot(gx - maze.target[0], gy - maze.target[1]) <= maze.target_radius)
    if not goal.any():
        dist = np.full(free.shape, np.inf)
        return Field(xs, ys, clear, free, dist, np.full(free.shape, -1), snap)
    dist, pred, _ = dijkstra(
        graph, directed=False, indices=index[goal], min_only=True, return_predecessors=True
    )
    return Field(xs, ys, clear, free, dist.reshape(ny, nx), pred.reshape(ny, nx), snap)


def _visible(field: Field, a: np.ndarray, b: np.ndarray) -> bool:
    """True if the straight segment a-b stays on free cells."""
    cell = field.xs[1] - field.xs[0]
    n = max(2, int(np.hypot(*(b - a)) / (0.5 * cell)) + 2)
    t = np.linspace(0.0, 1.0, n)[:, None]
    p = a + t * (b - a)
    i = np.clip(np.rint((p[:, 0] - field.xs[0]) / cell).astype(int), 0, len(field.xs) - 1)
    j = np.clip(np.rint((p[:, 1] - field.ys[0]) / cell).astype(int), 0, len(field.ys) - 1)
    return bool(field.free[j, i].all())


def taut_path(field: Field, x: float, y: float) -> np.ndarray:
    """``(k, 2)`` corners of the grid path from ``(x, y)``, pulled straight between them."""
    path = field.grid_path(x, y)
    corners = [0]
    while corners[-1] < len(path) - 1:
        i, j = corners[-1], corners[-1] + 1
        # Greedy: go as far along the grid path as is visible from the last corner.
        while j + 1 < len(path) and _visible(field, path[i], path[j + 1]):
            j += 1
        corners.append(j)
    return path[corners]


def path_stats(points: np.ndarray, min_turn_deg: float = 30.0, merge: float = 0.25):
    """Length (m), number of turns and total turning (deg) of a polyline.

    A path that wraps around a wall end bends at several corners a few cm apart; bends of
    one sign closer than ``merge`` m count as one turn, and turns under ``min_turn_deg`` are
    not counted (they still add to the total turning).
    """
    d = np.diff(points, axis=0)
    step = np.hypot(d[:, 0], d[:, 1])
    heading = np.arctan2(d[:, 1], d[:, 0])
    bend = (np.diff(heading) + np.pi) % (2 * np.pi) - np.pi  # rad, at points[1:-1]
    turns, current = [], 0.0
    for k, b in enumerate(bend):
        if abs(b) < 1e-3:  # rad; a straight run through a grid corner is no bend
            continue
        if current and (np.sign(b) != np.sign(current) or step[k] > merge):
            turns.append(current)
            current = 0.0
        current += b
    turns.append(current)
    count = int((np.degrees(np.abs(turns)) >= min_turn_deg).sum())
    return float(step.sum()), count, float(np.degrees(np.abs(bend)).sum())


def wall_followers(maze: Maze, keep: float = FOLLOW) -> dict[str, float]:
    """Path length (m) of a left- and a right-hand wall follower to the target.

    The follower keeps ``keep`` m from the wall surfaces, so it runs along the contour of the
    clearance field at that level (contourpy, a matplotlib dependency). It starts on the contour
    nearest the nominal start (the outer boundary) and goes either way until it passes within
    ``target_radius`` of the target; inf if it never does.
    """
    import contourpy

    xs, ys, clear = clearance_grid(maze)
    lines = contourpy.contour_generator(xs, ys, clear).lines(keep)
    sx, sy = maze.start_pose[:2]
    line = min(lines, key=lambda p: np.hypot(p[:, 0] - sx, p[:, 1] - sy).min())
    closed = np.allclose(line[0], line[-1])
    pts = line[:-1] if closed else line
    seg = np.hypot(*np.diff(np.vstack([pts, pts[:1]]), axis=0).T)
    start = int(np.argmin(np.hypot(pts[:, 0] - sx, pts[:, 1] - sy)))
    near = np.hypot(pts[:, 0] - maze.target[0], pts[:, 1] - maze.target[1]) <= maze.target_radius
    # Which hand touches the wall when going forward along the line: walls lie down-gradient.
    gy, gx = np.gradient(clear, ys, xs)
    i = int(np.clip(np.searchsorted(xs, pts[start, 0]), 0, len(xs) - 1))
    j = int(np.clip(np.searchsorted(ys, pts[start, 1]), 0, len(ys) - 1))
    ahead = pts[(start + 1) % len(pts)] - pts[start]
    wall_on_left = ahead[0] * -gy[j, i] - ahead[1] * -gx[j, i] > 0
    out = {}
    for direction in (1, -1):
        length, k = 0.0, start
        for _ in range(len(pts)):
            if near[k]:
                break
            step = seg[k] if direction == 1 else seg[(k - 1) % len(pts)]
            k = (k + direction) % len(pts)
            if not closed and k in (0, len(pts) - 1):
                length = math.inf
                break
            length += step
        else:
            length = math.inf
        hand = "left" if (direction == 1) == wall_on_left else "right"
        out[hand] = length
    return out


def start_cells(maze: Maze, field: Field, robot_radius: float = ROBOT_RADIUS) -> np.ndarray:
    """``(ny, nx)`` bool: cells of the start region whose centre clears the robot."""
    gx, gy = np.meshgrid(field.xs, field.ys)
    return (
        (maze.start_x[0] <= gx)
        & (gx <= maze.start_x[1])
        & (maze.start_y[0] <= gy)
        & (gy <= maze.start_y[1])
        & (field.clearance >= robot_radius)
    )


def _snap_disc(field: Field) -> np.ndarray:
    cell = field.xs[1] - field.xs[0]
    r = int(field.snap / cell)
    dj, di = np.mgrid[-r : r + 1, -r : r + 1]
    return np.hypot(di, dj) * cell <= field.snap + 1e-9


def stranded_starts(maze: Maze, field: Field, robot_radius: float = ROBOT_RADIUS) -> int:
    """Number of cells in the start region, clear of the robot, that cannot reach the target.

    A start counts as reaching the target if a reachable free cell is within ``field.snap``
    m, as in :meth:`Field.distance_from`.
    """
    near = binary_dilation(np.isfinite(field.distance), structure=_snap_disc(field))
    return int((start_cells(maze, field, robot_radius) & ~near).sum())


def snapped_distance(field: Field) -> np.ndarray:
    """``(ny, nx)`` distance (m) to the target from each cell, via the best free cell near it.

    The best free cell within ``field.snap`` (a min filter over the snap disc); inf where
    there is none. Computed once per field.
    """
    return field.snapped


def longest_start_path(maze: Maze, field: Field, robot_radius: float = ROBOT_RADIUS) -> float:
    """The longest shortest path (m) from any start cell that clears the robot.

    Each start cell takes the best free cell within ``field.snap`` m, as
    :meth:`Field.distance_from` does; inf if some start cannot reach the target.
    """
    best = snapped_distance(field)
    region = start_cells(maze, field, robot_radius)
    return float(best[region].max()) if region.any() else math.inf


def backtrack(field: Field) -> float:
    """Deepest dead end (m): the most any free cell's shortest path runs leftwards.

    The target is on the right, so a goal-seeking robot that has driven into a pocket must
    back out by this much along x before it can make progress again.
    """
    order = np.argsort(field.distance, axis=None)
    order = order[np.isfinite(field.distance.flat[order])]
    gx = np.broadcast_to(field.xs, field.free.shape).ravel()
    lowest = gx.copy()
    towards = field.towards.ravel()
    for k in order:  # cells nearer the target first, so the next cell is already done
        nxt = towards[k]
        if nxt >= 0:
            lowest[k] = min(gx[k], lowest[nxt])
    finite = np.isfinite(field.distance.ravel())
    return float((gx - lowest)[finite].max())


def report(maze: Maze) -> dict[str, float]:
    """Figures of one maze for the docs and the test log."""
    field = solve(maze)
    sx, sy = maze.start_pose[:2]
    length, turns, turning = path_stats(taut_path(field, sx, sy))
    follow = wall_followers(maze)
    return {
        "width": maze.size()[0],
        "height": maze.size()[1],
        "walls": len(maze.walls),
        "grid_path": field.distance_from(sx, sy),
        "path": length,
        "turns": turns,
        "turning_deg": turning,
        "gap": narrowest_gap(maze, cell=0.0025),
        "backtrack": backtrack(field),
        "left_follower": follow["left"],
        "right_follower": follow["right"],
    }


if __name__ == "__main__":
    import sys

    from sim_bridge.maze import load_named_maze, maze_names

    for name in sys.argv[1:] or maze_names():
        r = report(load_named_maze(name))
        print(
            f"{name:10s} {r['width']:.2f} x {r['height']:.2f} m, {r['walls']} walls, "
            f"path {r['path']:.2f} m (grid {r['grid_path']:.2f}), {r['turns']} turns "
            f"({r['turning_deg']:.0f} deg), gap {r['gap']:.3f} m, "
            f"backtrack {r['backtrack']:.2f} m, followers L {r['left_follower']:.1f} "
            f"R {r['right_follower']:.1f} m"
        )
