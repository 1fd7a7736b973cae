"""Seeded maze generator: new mazes of the size and kind of a robot's own, each proven solvable.

A generated maze is an ordinary :class:`~sim_bridge.maze.Maze` (saved as a maze file, drawn
by :mod:`sim_bridge.maze_plot`), made for one robot (docs/design.md section 21):

* **Size and scale** come from the robot's registration: its default maze gives the inner
  width and height, the start region (relative to the left wall), the target radius, the
  narrowest gap (the narrow gaps here are 1.0-1.25 times it) and the shortest path (the
  longest path allowed from any start is 1.1 times it, and at most 2/3 of what the robot
  drives at its top speed in an episode); its footprint radius gives the margin every
  path keeps from the walls (1.2 times the radius; 0.06 m for the 4WS robots, as in
  ``tests/test_mazes.py``). For the 4WS robots that is an 11.1 x 1.39 m maze with
  0.27-0.33 m gaps and at most 16 m of path; for the hexapod 8.0 x 2.0 m, about 1 m gaps,
  at most 8.6 m.
* **Obstacles**, left to right after the start zone, one per slot: ``baffle`` (from the top
  or bottom wall, an opening at its tip), ``gap`` (a full-height wall with one narrow gap),
  ``diagonal`` (a leaning baffle), ``posts`` (one to three short free-standing walls),
  ``block`` (a closed box on a wall that forces a corridor around it), ``dead_end`` (a
  baffle with a shelf back towards the start: a pocket open towards the robot) and
  ``chamber`` (a wide open slot). On request (``serpentine``, a share of the draws; the
  standard mix, and so the held-out set, has none): ``serpentine``, two or three baffles
  from alternating walls 1.25 times the narrowest gap to 1.5 times the widest apart, the
  winding shafts of the paper's ``corridors`` maze (0.36 m shafts, 0.455 m lanes); the
  standard kinds set walls from opposite sides that close only rarely (about one maze in
  300; none in the held-out set, whose closest pair is 0.63 m apart) and never as close as
  ``corridors``. A 4WS-scale kind: the legged robots' mazes cannot hold it.
* **Targets** anywhere reachable: ``wall`` (close to a wall of the last chamber, as in the
  paper's mazes), ``open`` (far from every wall), ``behind`` (in the lee of the last
  obstacle, behind a turn around its tip) or ``anywhere`` (any clear point of the maze's
  right half, with obstacles beyond it).
* **Proof.** A maze is kept only if at least :data:`MIN_OBSTACLES` obstacles (open
  chambers not counted) lie before the target, and the clearance-aware path search
  (:mod:`offline_evolution.mazes.paths`) connects every start cell that clears the robot
  to the target, the longest such path is within the limit, and the narrowest gap on the
  widest route is at least the design's narrowest (less two grid cells); otherwise the
  draw is repeated from the same generator.

Maze ``k`` of seed ``s`` is drawn from ``numpy.random.default_rng([s, k])``, so it does not
depend on how many mazes are asked for: ``--count 10`` gives the first ten of ``--count 50``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from evorbc_ros.config import ConfigError
from sim_bridge.maze import Maze, load_named_maze, maze_from_dict

from .paths import (
    DistanceGrid,
    Field,
    distance_grid,
    longest_start_path,
    narrowest_gap,
    solve,
    stranded_starts,
)

#: Obstacle kinds, and how often each is drawn.
KINDS = ("baffle", "gap", "diagonal", "posts", "block", "dead_end", "chamber")
_KIND_WEIGHTS = (0.22, 0.18, 0.14, 0.14, 0.12, 0.1, 0.1)
#: Kinds drawn only when asked for (``generate_maze(serpentine=...)``): outside the standard
#: mix, so that the held-out set (docs/design.md section 21) stays what it was.
EXTRA_KINDS = ("serpentine",)
#: Largest serpentine share: above it few slots would hold anything else.
MAX_SERPENTINE = 0.9
#: A serpentine's shaft width (m, between its baffles): from this times the narrowest gap to
#: this times the widest (0.33-0.50 m for the wheeled robots' mazes, about the 0.36 m shafts
#: of ``corridors``).
_SHAFT = (1.25, 1.5)
#: A serpentine slot's length beyond the spacing, in widest shafts (room for two or three).
_SERPENTINE_LENGTH = (1.0, 2.2)
#: Where targets go, and how often.
TARGET_MODES = ("wall", "open", "behind", "anywhere")
_TARGET_WEIGHTS = (0.3, 0.25, 0.25, 0.2)
#: Draws per maze before giving up. Most draws that fail are cheap (too few obstacles
#: before the target: no path search). A robot whose maze is low for its footprint needs
#: many: the A1 a median of 60 and at most 496 over mazes 0-39 of seeds 1, 2 and 21021
#: (200 failed 9 % of them), the Laikago from its URDF (maze a1 x1.05) a median of 326
#: and at most 1,365 over 40; the 4WS robots 1. More draws change no maze that fewer found.
MAX_TRIES = 5000
#: Obstacles (not counting open chambers) that must lie before the target, so that no
#: maze is nearly empty: the hexapod's own maze has three baffles.
MIN_OBSTACLES = 3


@dataclass(frozen=True)
class MazeSpec:
    """What a robot's generated mazes look like (all lengths in m, maze frame).

    The inner free area is ``x in [-width/2, width/2]``, ``y in [-height/2, height/2]``;
    built by :func:`spec_for_robot`.
    """

    robot: str
    width: float
    height: float
    robot_radius: float  # footprint radius: starts keep it clear of walls
    margin: float  # clearance a proving path keeps from every wall surface
    narrow_gap: tuple[float, float]  # width of a gap in a full-height wall
    opening: tuple[float, float]  # free width at a baffle's tip
    spacing: tuple[float, float]  # between consecutive obstacles
    start_offset: float  # start region's left edge, from the inner left wall
    start_length: float  # start region's extent along x
    start_inset: float  # start region's distance from the top and bottom walls
    start_heading_deg: tuple[float, float]
    first_obstacle: float  # nothing nearer the inner left wall than this
    target_radius: float
    path_limit: float  # longest shortest path from any start
    cell: float = 0.01  # grid of the path search
    wall_thickness: float = 0.01
    scale: float = 1.0  # the robot's maze was scaled up this much to fit it
    #: Why the robot's maze was scaled (one line), for the run to report; "" when not.
    warning: str = field(default="", compare=False)

    @property
    def snap(self) -> float:
        """How far (m) a start may step to the nearest free cell (its clearance: the footprint).

        One grid cell of 0.01 m beyond the margin's slack, that cell scaled with the maze.
        """
        return self.margin - self.robot_radius + 0.01 * self.scale


@functools.lru_cache(maxsize=16)
def spec_for_robot(name: str) -> MazeSpec:
    """The generator's settings for a registered robot, from its registration.

    Sizes come from the robot's default maze, scaled up uniformly when the robot does not
    fit it (:mod:`~sim_bridge.maze_fit`: its start, or a route keeping 1.2 times the
    footprint radius; the spec's ``warning`` says so, for the caller to report), so
    corridors, gaps, openings, wall lengths, the start region and the target radius all
    grow with the footprint. A robot that fits its maze (every shipped robot) gets exactly
    the sizes of that maze. The longest path allowed is at most 2/3 of what the robot
    drives at its top speed in an episode; a scaled maze too long for that is shortened
    to it (docs/design.md section 21).

    Raises:
        ConfigError: the robot is unknown (naming the known ones), or its default maze
            is not solvable with its footprint at any scale (nothing to size mazes from).
    """
    from evorbc_ros.robots.registry import lookup

    robot = lookup(name)
    return sized_spec(name, robot.maze, robot.footprint_radius, robot.max_speed, robot.episode_time)


def sized_spec(
    name: str, maze_name: str, footprint_radius: float, max_speed: float, episode_time: float
) -> MazeSpec:
    """:func:`spec_for_robot` of a robot given by its fields, registered or not.

    Args:
        name: the robot's name (for messages and the spec).
        maze_name: its default maze (a shipped maze's name or a maze file).
        footprint_radius: m. max_speed: m/s. episode_time: s.

    Raises:
        ConfigError: as :func:`spec_for_robot`.
    """
    from sim_bridge.maze_fit import fitted_maze

    own = load_named_maze(maze_name)
    r = footprint_radius
    try:
        maze, scale, warning = fitted_maze(own, r, name)
    except ValueError as e:
        raise ConfigError(f"robot {name}: {e}; cannot size generated mazes from it") from None
    margin = 1.2 * r
    # m; the hexapod's 2 m maze needs less. A scaled maze keeps its grid in cells.
    cell = (0.01 if own.size()[1] < 1.8 else 0.02) * scale
    x0, y0, x1, y1 = maze.bounds()
    t = maze.wall_thickness
    inner_left, inner_h = x0 + t, (y1 - y0) - 2 * t
    field_ = solve(maze, cell, margin, margin - r + 0.01 * scale)
    path = field_.distance_from(*maze.start_pose[:2])
    if not math.isfinite(path):
        raise ConfigError(
            f"robot {name}: its maze {maze_name} has no path with {margin:.3f} m clearance; "
            "cannot size generated mazes from it"
        )
    gap = narrowest_gap(maze, cell)
    height = round(inner_h, 3)
    width = round((x1 - x0) - 2 * t, 3)
    reach = 2.0 / 3.0 * max_speed * episode_time  # m driven in 2/3 of T
    if scale > 1.0 and 1.1 * path > reach:
        # A scaled-up maze the robot cannot cross in time: shorter by the same ratio.
        width = round(width * reach / (1.1 * path), 3)
    return MazeSpec(
        robot=name,
        width=width,
        height=height,
        robot_radius=r,
        margin=margin,
        narrow_gap=(gap, 1.25 * gap),
        opening=(min(1.3 * gap, 0.55 * height), min(2.0 * gap, 0.6 * height)),
        spacing=(max(0.6 * height, 1.2 * gap), max(1.1 * height, 2.0 * gap)),
        start_offset=maze.start_x[0] - inner_left,
        start_length=maze.start_x[1] - maze.start_x[0],
        # At least the margin: a start in a corner of the region, clear of both walls by the
        # footprint, is then never more than the snap from a free cell (every shipped
        # robot's region but the TurtleBot3's already is).
        start_inset=max(0.0, min(maze.start_y[0] - (y0 + t), (y1 - t) - maze.start_y[1]), margin),
        start_heading_deg=tuple(math.degrees(h) for h in maze.start_heading),
        first_obstacle=maze.start_x[1] - inner_left + max(margin, 0.2),
        target_radius=maze.target_radius,
        path_limit=min(1.1 * path, reach),
        cell=cell,
        wall_thickness=t,
        scale=scale,
        warning=f"generated mazes: {warning}" if warning else "",
    )


@dataclass(frozen=True)
class GeneratedMaze:
    """A generated maze, what it holds and its proof figures."""

    maze: Maze
    kinds: tuple[str, ...]  # obstacle kinds, left to right
    target_mode: str
    longest_path: float  # m, the longest shortest path from a start cell
    narrowest_gap: float  # m, on the widest route
    tries: int = 1  # draws it took
    #: Path lengths to the target from anywhere (the proof's field, kept compact): what
    #: path-distance training fitness reads (docs/design.md section 22).
    grid: DistanceGrid | None = field(default=None, compare=False, repr=False)

    def as_dict(self) -> dict:
        """Plain-data summary (CLI output)."""
        return {
            "name": self.maze.name,
            "kinds": list(self.kinds),
            "target_mode": self.target_mode,
            "longest_path": round(self.longest_path, 3),
            "narrowest_gap": round(self.narrowest_gap, 3),
        }


@dataclass
class _Draft:
    """Walls (centre lines) and facts collected while a maze is drawn."""

    spec: MazeSpec
    walls: list = field(default_factory=list)
    kinds: list = field(default_factory=list)
    starts: list = field(default_factory=list)  # x (m) where each obstacle's slot begins
    # (x of the obstacle's downstream face, side it hangs from: +1 top, -1 bottom)
    last_face: tuple[float, int] | None = None

    def wall(self, x1, y1, x2, y2) -> None:
        self.walls.append([float(x1), float(y1), float(x2), float(y2)])


def _edge(spec: MazeSpec, side: int) -> float:
    """The y (m) of the top (+1) or bottom (-1) outer wall's centre line: walls start there."""
    return side * (0.5 * spec.height + 0.5 * spec.wall_thickness)


def _tip(spec: MazeSpec, side: int, opening: float) -> float:
    """The y (m) of the tip of a baffle from ``side`` leaving ``opening`` m free at its tip."""
    return side * (opening - 0.5 * spec.height)


def _place(draft: _Draft, kind: str, a: float, b: float, rng: np.random.Generator) -> None:
    """Draw an obstacle of ``kind`` into the slot ``[a, b]`` (m along x)."""
    s, h = draft.spec, draft.spec.height
    c = 0.5 * (a + b)
    side = int(rng.choice((-1, 1)))
    opening = rng.uniform(*s.opening)
    if kind == "baffle":
        draft.wall(c, _edge(s, side), c, _tip(s, side, opening))
        draft.last_face = (c, side)
    elif kind == "gap":
        w = rng.uniform(*s.narrow_gap)
        piece = 0.05 * h  # m, the shortest piece of wall left beside a gap
        yc = rng.uniform(-0.5 * h + 0.5 * w + piece, 0.5 * h - 0.5 * w - piece)
        draft.wall(c, _edge(s, 1), c, yc + 0.5 * w)
        draft.wall(c, yc - 0.5 * w, c, _edge(s, -1))
        # The lee of a gap wall: the side away from its gap.
        draft.last_face = (c, -1 if yc > 0 else 1)
    elif kind == "diagonal":
        lean = rng.uniform(0.25, 0.45) * (b - a) * rng.choice((-1, 1))
        draft.wall(c - lean, _edge(s, side), c + lean, _tip(s, side, opening))
        draft.last_face = (max(c - lean, c + lean), side)
    elif kind == "posts":
        for _ in range(int(rng.integers(1, 4))):
            length = rng.uniform(0.1, 0.3) * h
            x = rng.uniform(a + 0.2 * (b - a), b - 0.2 * (b - a))
            y = rng.uniform(-0.25 * h, 0.25 * h)
            if rng.random() < 0.6:
                draft.wall(x, y - 0.5 * length, x, y + 0.5 * length)
            else:
                draft.wall(x - 0.5 * length, y, x + 0.5 * length, y)
        draft.last_face = None
    elif kind == "block":
        half = 0.5 * rng.uniform(0.3, 0.6) * (b - a)
        y = _tip(s, side, opening)
        draft.wall(c - half, _edge(s, side), c - half, y)
        draft.wall(c - half, y, c + half, y)
        draft.wall(c + half, y, c + half, _edge(s, side))
        draft.last_face = (c + half, side)
    elif kind == "dead_end":
        # A baffle at the slot's right end and a shelf from its tip back towards the start:
        # the pocket between the shelf and the wall is open towards the robot.
        x = b - 0.15 * (b - a)
        y = _tip(s, side, opening)
        shelf = rng.uniform(0.4, 0.75) * (x - a)
        draft.wall(x, _edge(s, side), x, y)
        draft.wall(x, y, x - shelf, y)
        draft.last_face = (x, side)
    elif kind == "serpentine":
        w = rng.uniform(_SHAFT[0] * s.narrow_gap[0], _SHAFT[1] * s.narrow_gap[1])
        # Two baffles, or three when the slot holds them with its spacing kept around them.
        n = 3 if (b - a) - s.spacing[0] >= 2 * w else 2
        for i in range(n):
            x = c + (i - 0.5 * (n - 1)) * w
            draft.wall(x, _edge(s, side), x, _tip(s, side, opening))
            draft.last_face = (x, side)
            side = -side
    elif kind == "chamber":
        draft.last_face = None
    else:  # pragma: no cover - KINDS lists every kind
        raise ValueError(kind)
    draft.kinds.append(kind)
    draft.starts.append(a)


def _slot_length(kind: str, spec: MazeSpec, rng: np.random.Generator) -> float:
    """Length (m, along x) ``kind`` takes, its share of free space around it included."""
    base = rng.uniform(*spec.spacing)
    if kind in ("block", "dead_end"):
        return base * 1.5
    if kind == "chamber":
        return rng.uniform(1.0, 1.6) * spec.height
    if kind == "serpentine":  # room for two or three shafts besides the spacing
        return base + rng.uniform(*_SERPENTINE_LENGTH) * _SHAFT[1] * spec.narrow_gap[1]
    return base


def _goal_room(spec: MazeSpec) -> float:
    """Free length (m, along x) kept before the right wall for the target's chamber."""
    return max(0.6 * spec.height, 2.0 * (spec.margin + spec.target_radius))


def check_serpentine(spec: MazeSpec, share: float) -> None:
    """Refuse a serpentine share out of range, or any for a robot whose mazes cannot hold them.

    A serpentine takes up to ``spacing + 3.3`` narrow gaps of length; :data:`MIN_OBSTACLES`
    of them must fit between the first obstacle and the goal room, or no draw with one
    passes (the hexapod's and the A1's 8 m mazes with their 1 m gaps: serpentines are a
    4WS-scale kind).

    Raises:
        ConfigError: naming the share, the range or the robot.
    """
    if not 0.0 <= share <= MAX_SERPENTINE:
        raise ConfigError(f"serpentine share must be in [0, {MAX_SERPENTINE}], got {share}")
    longest = spec.spacing[1] + _SERPENTINE_LENGTH[1] * _SHAFT[1] * spec.narrow_gap[1]
    room = spec.width - spec.first_obstacle - _goal_room(spec)
    if share > 0.0 and MIN_OBSTACLES * longest > room:
        raise ConfigError(
            f"serpentine: {spec.robot}'s mazes cannot hold serpentines ({MIN_OBSTACLES} of "
            f"up to {longest:.1f} m in {room:.1f} m); use 0 for this robot"
        )


def _kind_weights(serpentine: float) -> tuple[tuple[str, ...], np.ndarray]:
    """The kinds drawn and their probabilities, with ``serpentine`` of the draws serpentines."""
    if serpentine == 0.0:
        return KINDS, np.asarray(_KIND_WEIGHTS)
    weights = [w * (1.0 - serpentine) for w in _KIND_WEIGHTS] + [serpentine]
    return (*KINDS, *EXTRA_KINDS), np.asarray(weights)


def _maze_data(draft: _Draft, name: str, target: tuple[float, float], note: str) -> dict:
    s = draft.spec
    hw, hh, t = 0.5 * s.width, 0.5 * s.height, s.wall_thickness
    ox, oy = hw + 0.5 * t, hh + 0.5 * t
    boundary = [[-ox, oy, ox, oy], [ox, oy, ox, -oy], [ox, -oy, -ox, -oy], [-ox, -oy, -ox, oy]]
    boundary = [[round(v, 4) for v in w] for w in boundary]
    x0 = -hw + s.start_offset
    y0, y1 = -hh + s.start_inset, hh - s.start_inset
    return {
        "name": name,
        "description": note,
        "wall_thickness": t,
        "walls": boundary + [[round(v, 4) for v in w] for w in draft.walls],
        "start": {
            "pose": [round(x0 + 0.5 * s.start_length, 4), 0.0, 0.0],
            "region": {
                "x": [round(x0, 4), round(x0 + s.start_length, 4)],
                "y": [round(y0, 4), round(y1, 4)],
                "heading_deg": list(s.start_heading_deg),
            },
        },
        "target": [round(target[0], 4), round(target[1], 4)],
        "target_radius": s.target_radius,
    }


def _clear_point(
    maze: Maze, rng: np.random.Generator, x_range, clearance, tries: int = 400
) -> tuple[float, float] | None:
    """A point with ``x`` in ``x_range`` whose clearance lies in ``clearance`` (m), or None."""
    hh = 0.5 * (maze.bounds()[3] - maze.bounds()[1])
    for _ in range(tries):
        x, y = rng.uniform(*x_range), rng.uniform(-hh, hh)
        if clearance[0] <= maze.clearance(x, y) <= clearance[1]:
            return x, y
    return None


def _target(draft: _Draft, mode: str, walls_maze: Maze, goal_from: float, rng) -> tuple | None:
    """The target for ``mode``, or None if this draft has no room for one."""
    s = draft.spec
    hw, hh = 0.5 * s.width, 0.5 * s.height
    near_wall = (1.5 * s.margin, 1.5 * s.margin + s.target_radius)  # m from a wall surface
    if mode == "wall":
        return _clear_point(walls_maze, rng, (goal_from, hw), near_wall)
    if mode == "open":
        return _clear_point(walls_maze, rng, (goal_from, hw), (0.3 * s.height, math.inf))
    if mode == "behind":
        if draft.last_face is None:
            return None
        x, side = draft.last_face
        if 0.35 * s.height <= near_wall[0]:
            return None  # a robot this large for its maze's height has no room behind a face
        tx = x + rng.uniform(*near_wall)
        ty = side * (hh - rng.uniform(near_wall[0], 0.35 * s.height))
        if walls_maze.clearance(tx, ty) < near_wall[0]:
            return None
        return tx, ty
    return _clear_point(walls_maze, rng, (0.0, hw), (near_wall[0], math.inf))


def _draw(
    spec: MazeSpec, rng: np.random.Generator, name: str, serpentine: float = 0.0
) -> tuple[dict, _Draft, str]:
    """One draft maze (not yet proven)."""
    kinds, weights = _kind_weights(serpentine)
    hw = 0.5 * spec.width
    draft = _Draft(spec)
    x = -hw + spec.first_obstacle
    goal_room = _goal_room(spec)
    while True:
        kind = str(rng.choice(kinds, p=weights))
        length = _slot_length(kind, spec, rng)
        if x + length > hw - goal_room:
            break
        _place(draft, kind, x, x + length, rng)
        x += length
    mode = str(rng.choice(TARGET_MODES, p=_TARGET_WEIGHTS))
    walls_only = maze_from_dict(_maze_data(draft, name, (hw - 0.5 * goal_room, 0.0), ""), name)
    target = _target(draft, mode, walls_only, x + 0.5 * spec.margin, rng)
    if target is None:
        mode = "wall"
        target = _target(draft, mode, walls_only, x + 0.5 * spec.margin, rng)
    note = f"generated for {spec.robot}: {', '.join(draft.kinds) or 'no obstacles'}; target {mode}"
    return _maze_data(draft, name, target or (hw - 0.5 * goal_room, 0.0), note), draft, mode


def generate_maze(
    spec: MazeSpec, seed: int, index: int, prefix: str = "gen", serpentine: float = 0.0
) -> GeneratedMaze:
    """Maze ``index`` of ``seed`` for ``spec``, proven solvable (see the module docstring).

    ``serpentine`` (in [0, :data:`MAX_SERPENTINE`]) is the share of obstacle draws that are
    serpentines; 0, the default, is the standard mix (the same mazes as before the kind
    existed).

    Raises:
        RuntimeError: no draw in :data:`MAX_TRIES` passed the proof (a spec too tight).
        ConfigError: a serpentine share out of range or for a robot that cannot hold one
            (:func:`check_serpentine`).
    """
    check_serpentine(spec, serpentine)
    rng = np.random.default_rng([seed, index])
    name = f"{prefix}{seed}-{index:03d}"
    for attempt in range(1, MAX_TRIES + 1):
        data, draft, mode = _draw(spec, rng, name, serpentine)
        before = [
            k for k, a in zip(draft.kinds, draft.starts, strict=True) if a < data["target"][0]
        ]
        if sum(k != "chamber" for k in before) < MIN_OBSTACLES:
            continue  # too easy: draw again
        try:
            maze = maze_from_dict(data, name)
        except ConfigError:
            continue  # a target or start inside a wall: draw again
        proof = _proof(maze, spec)
        if proof is not None:
            longest, gap, field_ = proof
            grid = distance_grid(field_)
            return GeneratedMaze(maze, tuple(draft.kinds), mode, longest, gap, attempt, grid)
    raise RuntimeError(f"no solvable maze for {spec.robot} in {MAX_TRIES} draws (seed {seed})")


def _proof(maze: Maze, spec: MazeSpec) -> tuple[float, float, Field] | None:
    """``(longest path m, narrowest gap m, path field)`` if ``maze`` is solvable, else None.

    Solvable: every start cell that clears the robot reaches the target keeping
    ``spec.margin`` from the walls, within ``spec.path_limit``, and the widest route's
    narrowest gap is at least the design's narrowest less two grid cells.
    """
    field_ = solve(maze, spec.cell, spec.margin, spec.snap)
    if stranded_starts(maze, field_, spec.robot_radius):
        return None
    longest = longest_start_path(maze, field_, spec.robot_radius)
    if not longest <= spec.path_limit:
        return None
    gap = narrowest_gap(maze, spec.cell)
    if gap < spec.narrow_gap[0] - 2 * spec.cell:
        return None
    return longest, gap, field_


def generate_mazes(
    robot: str, count: int, seed: int, prefix: str = "gen", serpentine: float = 0.0
) -> list[GeneratedMaze]:
    """``count`` proven mazes for ``robot``: mazes ``0 .. count-1`` of ``seed``."""
    spec = spec_for_robot(robot)
    return [generate_maze(spec, seed, k, prefix, serpentine) for k in range(count)]
