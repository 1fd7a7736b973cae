"""Mazes that fit the robot: the smallest uniform scale-up a maze needs (docs/design.md section 21).

Offline runs (:func:`offline_evolution.maze_task.base.fit_task_mazes`) and the simulation
bridge (:mod:`sim_bridge.bridge_node`, ``evorbc-sim``) fit a maze with the same code, so a
lockstep run drives the very maze of the offline episode (docs/design.md section 9).

A maze *fits* a robot of footprint radius ``r`` (m) when

* its nominal start clears the footprint (``r`` from every wall surface: replay, the
  post-selection and the ROS bridge start there), and
* a route from the start region to the target disc keeps :data:`MARGIN_RATIO` ``* r``
  from every wall surface: the clearance the generator's proof keeps
  (``offline_evolution.mazes.generator``), so that the narrowest gap on the way is at
  least ``2.4 r`` wide.

A maze that does not fit is scaled about the maze frame's origin by the smallest factor
``s > 1`` that makes it fit: walls (centre lines and thickness), the start pose and region
and the target with its radius, so every distance grows by ``s`` and nothing else
changes. Since clearances scale with ``s``, ``s`` is read off the unscaled maze:
``max(r / c_start, 2 * MARGIN_RATIO * r / g)`` for the start's clearance ``c_start`` and the
narrowest gap ``g`` on the widest route (which the grid search reads low by up to a cell,
so ``s`` errs on the large side), rounded up to 0.001. A maze walled shut (no route at
any width, as a test of a wall stopping the robot) is scaled for its start only.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.ndimage import distance_transform_edt, label

from evorbc_ros.config import ConfigError
from sim_bridge.geometry import box_corners, box_distances
from sim_bridge.maze import Maze, load_named_maze

#: A route keeps this times the footprint radius from the walls (the generator's margin).
MARGIN_RATIO = 1.2
#: Grid cells across the maze's longer side at most, for the gap search (m per cell:
#: 0.01 for mazes up to 20 m, the shipped ones being 8-11 m).
_MAX_CELLS = 2000
#: Cell-wall distance tests the exact gap search may make (about a second; the shipped
#: mazes take 3 M); a maze beyond it is searched on :func:`_raster_clearance`.
_EXACT_WORK = 50_000_000


def clearance_grid(maze: Maze, cell: float = 0.01) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cell centres ``xs (nx,)``, ``ys (ny,)`` and the clearance ``(ny, nx)`` in m."""
    x0, y0, x1, y1 = maze.bounds()
    xs = x0 + (np.arange(math.ceil((x1 - x0) / cell)) + 0.5) * cell
    ys = y0 + (np.arange(math.ceil((y1 - y0) / cell)) + 0.5) * cell
    gx, gy = np.meshgrid(xs, ys)
    px, py = gx.ravel(), gy.ravel()
    near = np.full(px.shape, np.inf)
    for box in maze.boxes:
        np.minimum(near, box_distances(px, py, box), out=near)
    return xs, ys, near.reshape(gx.shape)


def narrowest_gap(maze: Maze, cell: float = 0.01, resolution: float = 0.001, grid=None) -> float:
    """Width (m, wall surface to wall surface) of the narrowest gap on the widest route.

    Twice the largest clearance that still connects the start region to the target: the
    robot cannot avoid a gap this narrow, and need not pass a narrower one. Cell centres
    miss a gap's middle by up to half a cell each way, so this reads low by up to ``cell``.
    ``grid``: the ``(xs, ys, clearance)`` to search, if not :func:`clearance_grid`'s.
    """
    xs, ys, clear = grid if grid is not None else clearance_grid(maze, cell)
    gx, gy = np.meshgrid(xs, ys)
    start = (
        (maze.start_x[0] <= gx)
        & (gx <= maze.start_x[1])
        & (maze.start_y[0] <= gy)
        & (gy <= maze.start_y[1])
    )
    goal = np.hypot(gx - maze.target[0], gy - maze.target[1]) <= maze.target_radius
    structure = np.ones((3, 3), bool)  # 8-connectivity, as in :func:`solve`

    def connected(level: float) -> bool:
        labels, _ = label(clear >= level, structure)
        ends = set(labels[start & (clear >= level)]) & set(labels[goal & (clear >= level)])
        return bool(ends - {0})

    lo, hi = 0.0, float(clear.max())
    while hi - lo > resolution / 2:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if connected(mid) else (lo, mid)
    return 2.0 * lo


def _raster_clearance(maze: Maze, cell: float):
    """``(xs, ys, clearance)`` on a grid, each wall visiting only the cells by it.

    Cells within ``2 * cell`` of a wall's box hold their exact distance; the rest the
    distance (m) to the nearest such cell plus ``2 * cell``, by a Euclidean distance
    transform: a maze of thousands of walls costs its cells, not cells times walls.
    """
    x0, y0, x1, y1 = maze.bounds()
    xs = x0 + (np.arange(math.ceil((x1 - x0) / cell)) + 0.5) * cell
    ys = y0 + (np.arange(math.ceil((y1 - y0) / cell)) + 0.5) * cell
    near = np.full((len(ys), len(xs)), np.inf)
    reach = 2.0 * cell
    for box, corners in zip(maze.boxes, box_corners(maze.boxes), strict=True):
        lo, hi = corners.min(axis=0) - reach, corners.max(axis=0) + reach
        i0, i1 = np.searchsorted(xs, lo[0]), np.searchsorted(xs, hi[0])
        j0, j1 = np.searchsorted(ys, lo[1]), np.searchsorted(ys, hi[1])
        gx, gy = np.meshgrid(xs[i0:i1], ys[j0:j1])
        d = box_distances(gx, gy, box)
        d[d > reach] = np.inf
        np.minimum(near[j0:j1, i0:i1], d, out=near[j0:j1, i0:i1])
    far = distance_transform_edt(~np.isfinite(near)) * cell + reach
    return xs, ys, np.where(np.isfinite(near), near, far)


def _room(maze: Maze) -> tuple[float, float]:
    """``(start clearance m, narrowest gap m on the widest route)`` of ``maze`` as it is."""
    x, y, _ = maze.start_pose
    cell = max(0.01, max(maze.size()) / _MAX_CELLS)
    cells = math.ceil(maze.size()[0] / cell) * math.ceil(maze.size()[1] / cell)
    grid = None
    if cells * len(maze.walls) > _EXACT_WORK:
        grid = _raster_clearance(maze, cell)
    return maze.clearance(x, y), narrowest_gap(maze, cell, grid=grid)


def fit_scale(maze: Maze, robot_radius: float) -> float:
    """The smallest factor (>= 1, in steps of 0.001) by which ``maze`` fits the robot.

    Args:
        maze: the maze, as loaded.
        robot_radius: m, the robot's footprint radius.

    Returns:
        1.0 exactly if the maze fits as it is, else the factor (see the module docstring).
        ``math.inf`` if no scale helps (the start inside a wall). A maze with no way from
        the start region to the target at all is scaled for its start only.
    """
    start_room, gap = _room(maze)
    if start_room <= 0:
        return math.inf
    need = robot_radius / start_room
    if gap > 0:  # a maze walled shut (a test of a wall stopping the robot) scales for its start
        need = max(need, 2.0 * MARGIN_RATIO * robot_radius / gap)
    if need <= 1.0:
        return 1.0
    return math.ceil(need * 1000.0 - 1e-9) / 1000.0


def scaled_maze(maze: Maze, factor: float, why: str = "") -> Maze:
    """``maze`` with every length times ``factor`` about the maze frame's origin.

    Walls ``(m, 4)``, wall thickness, start pose and region, target and target radius scale;
    headings do not. The name stays (traces and results name the maze); the description
    says the factor and ``why``.
    """
    if factor == 1.0:
        return maze
    note = f"scaled x{factor:g}" + (f" ({why})" if why else "")
    return dataclasses.replace(
        maze,
        walls=np.asarray(maze.walls, dtype=np.float64) * factor,
        wall_thickness=maze.wall_thickness * factor,
        start_pose=(maze.start_pose[0] * factor, maze.start_pose[1] * factor, maze.start_pose[2]),
        start_x=(maze.start_x[0] * factor, maze.start_x[1] * factor),
        start_y=(maze.start_y[0] * factor, maze.start_y[1] * factor),
        target=(maze.target[0] * factor, maze.target[1] * factor),
        target_radius=maze.target_radius * factor,
        description=f"{maze.description}; {note}" if maze.description else note,
    )


def misfit_reason(maze: Maze, robot_radius: float) -> str:
    """Why ``maze`` as it is does not fit (for the warning): what sets the factor."""
    start_room, gap = _room(maze)
    margin = MARGIN_RATIO * robot_radius
    if gap <= 0 or robot_radius / start_room >= 2.0 * margin / gap:
        return (
            f"its start is {start_room:.3f} m from a wall and the robot needs {robot_radius:.3f} m"
        )
    return (
        f"its narrowest gap on the way is {gap:.3f} m and the robot needs {2 * margin:.3f} m "
        f"({MARGIN_RATIO:g} x its {robot_radius:.3f} m footprint radius each side)"
    )


def fitted_maze(
    maze: Maze, robot_radius: float, robot: str = "the robot", factor: float | None = None
) -> tuple[Maze, float, str | None]:
    """``(maze, factor, warning)``: ``maze`` scaled to fit, its factor and a one-line warning.

    ``factor``: a recorded factor to apply as it is (a run's recorded task, replayed), or
    None to compute it with :func:`fit_scale`. The warning is None when nothing was scaled.

    Raises:
        ValueError: no scale makes the maze fit (naming the maze and the robot).
    """
    if factor is None:
        factor = fit_scale(maze, robot_radius)
    if not math.isfinite(factor):
        raise ValueError(
            f"maze {maze.name}: no scale fits robot {robot} (its start touches a wall)"
        )
    if factor == 1.0:
        return maze, 1.0, None
    why = misfit_reason(maze, robot_radius)
    warning = f"maze {maze.name} scaled x{factor:g} to fit robot {robot}: {why}"
    return scaled_maze(maze, factor, f"to fit {robot}"), factor, warning


def load_fitted_maze(
    name: str, robot_radius: float, robot: str = "the robot", factor: float | None = None
) -> tuple[Maze, float, str | None]:
    """:func:`fitted_maze` of the maze ``name`` (a shipped maze's name or a maze file).

    What the simulation bridge and ``evorbc-sim`` run: the maze of the offline episode. As
    in offline runs, a given (recorded) ``factor`` is applied without a warning: the
    warning is only for a factor computed here.

    Raises:
        ConfigError: the maze does not load, or no scale makes it fit (one line).
    """
    try:
        maze, used, warning = fitted_maze(load_named_maze(name), robot_radius, robot, factor)
    except ValueError as e:
        raise ConfigError(str(e)) from None
    return maze, used, warning if factor is None else None
