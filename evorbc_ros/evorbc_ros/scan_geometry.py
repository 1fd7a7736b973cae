"""What an off-centre scanner saw, as geometry in the body frame (docs/laser.md).

A rangefinder of the sensor layout is a set of rays from the body centre that start at the
mount ring (``mount_radius``), as the offline simulator casts them (docs/design.md section 5).
When the scanner sits elsewhere on the body, no beam runs along such a ray, so the laser
node rebuilds the scanner's view and casts the rays into it:

* The **boundary** of the free space the scanner saw, made of straight pieces (m, body
  frame). The hits of two neighbouring valid beams are joined into one *surface* piece when
  they plausibly lie on one surface: the adaptive breakpoint rule of Borges & Aldon (2004),
  which joins them unless they are farther apart than a surface seen at the grazing angle
  :data:`GRAZING_ANGLE` would put them, plus three standard deviations of range noise
  (:data:`RANGE_SIGMA`). Otherwise (a depth jump) each beam keeps its range over its half of
  the gap, and a radial *shadow* edge joins the two ranges: what lies behind a jump was not
  seen, so the edge is taken as an obstacle (conservative). A beam with no return (+inf, or
  beyond ``range_max``) is free space out to ``range_max`` and adds no obstacle; a ``-inf``
  beam (closer than ``range_min``) is an obstacle at the scanner.
* **Unknown** wedges (seen from the scanner): directions farther than the tolerance from
  every valid beam. Invalid beams (NaN, below ``range_min``) within the tolerance of a valid
  beam are bridged as if they were not there (the gap is joined or split as above).

A ray reads its first crossing with an obstacle piece; a field of view reads the nearest
obstacle point inside its wedge. A ray is blind when the point it reads (its first hit, or
the end of its range) lies in an unknown wedge: no valid beam covers it. (A ray that only
crosses an unknown wedge on its way, as rays from the mount ring do near an off-centre
scanner, is read like a clean scan's ray crossing the gaps between its beams.) Parts of a
ray outside the scan's span see nothing.

Everything is vectorised with numpy over beams and pieces; ``bench/bench_laser.py``
measures it.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

#: Beam kinds (REP 117): no information, a hit, no return within range, closer than range_min.
INVALID, HIT, OPEN, TOUCHING = 0, 1, 2, 3

#: Breakpoint rule (Borges & Aldon 2004): the most grazing view (rad, between the beam and
#: the surface) at which two neighbouring hits still count as one surface. 10 deg is the
#: value commonly used with 2D lidars; surfaces seen more obliquely are split into half-gap
#: pieces with a shadow edge, which errs towards nearer obstacles.
GRAZING_ANGLE = math.radians(10.0)
#: Range noise (m, one standard deviation) allowed for by the breakpoint rule; typical of
#: indoor 2D lidars (1-3 cm). Noise-free scans are unaffected by it on flat walls.
RANGE_SIGMA = 0.01
#: Slack (m, and in the segment parameter) so that a ray through a shared vertex of two
#: pieces meets at least one of them despite rounding.
EPS = 1e-9


def _cross(ax, ay, bx, by):
    """2D cross product ``a x b`` (broadcasting)."""
    return ax * by - ay * bx


@dataclass(frozen=True)
class ScanBeams:
    """A scan's beams in the body frame, counter-clockwise (computed once per span).

    Attributes:
        origin: ``(2,)`` scanner position in the body frame, m.
        index: ``(n,)`` message index of each beam, in counter-clockwise order (beams past a
            full turn, duplicates of the first ones, are left out).
        in_order: ``index`` is every message index in order (no reordering needed).
        angle, cos, sin: ``(n,)`` beam directions in the body frame, rad, increasing.
        spacing: angle between neighbouring beams, rad (> 0).
        closed: the beams go round the whole circle, so the last neighbours the first.
        lo, hi: edges of the span (rad), half a spacing beyond the outer beams.
    """

    origin: np.ndarray
    index: np.ndarray
    in_order: bool
    angle: np.ndarray
    cos: np.ndarray
    sin: np.ndarray
    spacing: float
    closed: bool
    lo: float
    hi: float

    @classmethod
    def from_scan(
        cls, heading: np.ndarray, angle_increment: float, x: float, y: float
    ) -> ScanBeams:
        """The beams of a scanner at ``(x, y)`` (m, body frame).

        Args:
            heading: ``(n,)`` beam directions in message order, rad, body frame.
            angle_increment: the message's increment (rad; its sign gives the order).
        """
        spacing = abs(float(angle_increment))
        index = np.arange(heading.size)
        if angle_increment < 0:
            index = index[::-1]
        # Beams a full turn or more after the first repeat directions already measured.
        keep = int(min(heading.size, math.ceil(2.0 * math.pi / spacing - 1e-9)))
        index = index[:keep]
        angle = heading[index]
        closed = 2.0 * math.pi - (keep - 1) * spacing <= spacing * (1.0 + 1e-3)
        return cls(
            origin=np.array([x, y], dtype=np.float64),
            index=index,
            in_order=keep == heading.size and angle_increment > 0,
            angle=angle,
            cos=np.cos(angle),
            sin=np.sin(angle),
            spacing=spacing,
            closed=closed,
            lo=float(angle[0]) - 0.5 * spacing,
            hi=float(angle[-1]) + 0.5 * spacing,
        )

    def outside(self) -> np.ndarray:
        """``(w, 2)`` wedges (rad, from the scanner) outside the span; none if closed."""
        if self.closed:
            return np.empty((0, 2))
        return split_wedges(np.array([[self.hi, self.lo + 2.0 * math.pi]]))


@dataclass(frozen=True)
class Boundary:
    """The obstacle pieces and unknown wedges of one scan.

    Attributes:
        ax, ay, ex, ey: ``(p,)`` obstacle pieces ``a + s e``, ``0 <= s <= 1``: start point
            and extent, m, body frame.
        unknown: ``(w, 2)`` wedges ``[lo, hi]`` (rad, seen from the scanner, each narrower
            than 90 deg) holding no valid beam within the tolerance.
    """

    ax: np.ndarray
    ay: np.ndarray
    ex: np.ndarray
    ey: np.ndarray
    unknown: np.ndarray


def split_wedges(wedges: np.ndarray, widest: float = 0.5 * math.pi) -> np.ndarray:
    """``(w, 2)`` wedges ``[lo, hi]`` (rad) cut into pieces no wider than ``widest``."""
    out = []
    for lo, hi in wedges:
        parts = max(1, math.ceil((hi - lo) / widest - 1e-12))
        edges = np.linspace(lo, hi, parts + 1)
        out += list(itertools.pairwise(edges))
    return np.array(out, dtype=np.float64).reshape(-1, 2)


def classify(
    ranges: np.ndarray, range_min: float, range_max: float
) -> tuple[np.ndarray, np.ndarray]:
    """Beam kinds and the ranges the boundary uses (REP 117).

    Returns:
        ``(n,)`` kinds (:data:`INVALID`, :data:`HIT`, :data:`OPEN`, :data:`TOUCHING`) and
        ``(n,)`` ranges, m: the range of a hit, ``range_max`` for no return, 0 for touching,
        NaN for invalid beams.
    """
    finite = np.isfinite(ranges)
    kind = np.full(ranges.shape, INVALID, dtype=np.int8)
    kind[finite & (ranges >= range_min)] = HIT
    kind[(finite & (ranges > range_max)) | np.isposinf(ranges)] = OPEN
    kind[np.isneginf(ranges)] = TOUCHING
    r = np.where(kind == HIT, ranges, np.nan)
    r = np.where(kind == OPEN, range_max, r)
    return kind, np.where(kind == TOUCHING, 0.0, r)


def build_boundary(
    beams: ScanBeams, kind: np.ndarray, r: np.ndarray, tolerance: float, reach: float = math.inf
) -> Boundary:
    """The obstacle pieces and unknown wedges of a scan.

    Args:
        beams: the scan's geometry.
        kind, r: ``(n,)`` message-order beam kinds and ranges from :func:`classify`.
        tolerance: how far (rad) a valid beam's view reaches over invalid neighbours.
        reach: pieces farther than this from the body centre (m) may be left out; no
            rangefinder ray reaches them.
    """
    if not beams.in_order:
        kind, r = kind[beams.index], r[beams.index]
    valid = kind != INVALID
    all_valid = bool(valid.all())
    if all_valid:
        psi, cos, sin = beams.angle, beams.cos, beams.sin
    else:
        valid = np.flatnonzero(valid)
        if valid.size == 0:
            lo = beams.lo
            whole = np.array([[lo, lo + 2.0 * math.pi if beams.closed else beams.hi]])
            empty = np.empty(0)
            return Boundary(empty, empty, empty, empty, split_wedges(whole))
        kind, r = kind[valid], r[valid]
        psi, cos, sin = beams.angle[valid], beams.cos[valid], beams.sin[valid]
    sx, sy = beams.origin
    px, py = sx + r * cos, sy + r * sin
    solid = kind != OPEN  # hits and touching: obstacles at their end point

    # Neighbouring valid beams (i, j) counter-clockwise, as slices of the arrays closed up
    # by the first beam when the scan goes round; the gap between them (rad).
    if beams.closed:
        px, py, r, solid, psi = (np.append(v, v[0]) for v in (px, py, r, solid, psi))
    i, j = slice(0, -1), slice(1, None)
    if all_valid:
        bridged = True
        gap = beams.spacing
        inferable = gap < GRAZING_ANGLE
        spread = math.sin(gap) / math.sin(GRAZING_ANGLE - gap) if inferable else 0.0
    else:
        index = np.append(valid, valid[0] + beams.index.size) if beams.closed else valid
        gap = np.diff(index) * beams.spacing
        bridged = gap <= 2.0 * tolerance + 1e-9
        inferable = bridged & (gap < GRAZING_ANGLE)
        spread = np.sin(gap) / np.sin(np.where(inferable, GRAZING_ANGLE - gap, 1.0))
    # Adaptive breakpoint distance (Borges & Aldon): the farthest apart two hits of one
    # surface can be; no surface is inferred across a gap of the grazing angle or more.
    ex, ey = px[j] - px[i], py[j] - py[i]
    joint = np.minimum(r[i], r[j]) * spread + 3.0 * RANGE_SIGMA
    surface = solid[i] & solid[j] & (ex * ex + ey * ey <= joint * joint) & inferable
    pieces = [(px[i][surface], py[i][surface], ex[surface], ey[surface])]
    unknown = []
    rest = ~surface & (solid[i] | solid[j] | ~bridged)
    if rest.any():
        k = np.flatnonzero(rest)
        gap = np.broadcast_to(gap, rest.shape)[k]
        bridged = np.broadcast_to(bridged, rest.shape)[k]
        ri, rj, si, sj = r[k], r[k + 1], solid[k], solid[k + 1]
        # Each side keeps its range over its half of the gap, or over the tolerance.
        half = np.where(bridged, 0.5 * gap, tolerance)
        ei = psi[k] + half  # end of beam i's piece
        ej = psi[k] + gap - half  # start of beam j's piece
        cix, ciy = sx + ri * np.cos(ei), sy + ri * np.sin(ei)
        cjx, cjy = sx + rj * np.cos(ej), sy + rj * np.sin(ej)
        for keep, x0, y0, x1, y1 in (
            (si, px[k], py[k], cix, ciy),  # beam i's range held
            (sj, cjx, cjy, px[k + 1], py[k + 1]),  # beam j's range held
            (bridged, cix, ciy, cjx, cjy),  # the radial shadow edge at mid-gap
        ):
            pieces.append((x0[keep], y0[keep], x1[keep] - x0[keep], y1[keep] - y0[keep]))
        if not bridged.all():
            unknown.append(np.stack([ei[~bridged], ej[~bridged]], axis=1))

    if not beams.closed:
        # The outer valid beams reach to the span's edges, or over the tolerance.
        for k, edge, sign in ((0, beams.lo, -1.0), (psi.size - 1, beams.hi, 1.0)):
            held = psi[k] + sign * min(tolerance, abs(psi[k] - edge))
            if solid[k]:
                hx, hy = sx + r[k] * math.cos(held), sy + r[k] * math.sin(held)
                pieces.append(tuple(np.array([v]) for v in (px[k], py[k], hx - px[k], hy - py[k])))
            if abs(psi[k] - edge) > tolerance:
                unknown.append(np.array([sorted((held, edge))]))
    if len(pieces) == 1:
        ax, ay, ex, ey = pieces[0]
    else:
        ax, ay, ex, ey = (np.concatenate(parts) for parts in zip(*pieces, strict=True))
    if math.isfinite(reach):
        # No point of a piece is nearer the centre than |a| - |e|.
        near = np.hypot(ax, ay) - np.hypot(ex, ey) <= reach
        ax, ay, ex, ey = ax[near], ay[near], ex[near], ey[near]
    unknown = split_wedges(np.concatenate(unknown)) if unknown else np.empty((0, 2))
    return Boundary(ax, ay, ex, ey, unknown)


def ray_hits(boundary: Boundary, ux: np.ndarray, uy: np.ndarray, start: float) -> np.ndarray:
    """``(r,)`` distance (m) from the body centre to the first obstacle along each ray.

    Args:
        ux, uy: ``(r,)`` unit ray directions (body frame); rays run from ``start`` m from
            the centre (the mount ring) outwards.

    Returns:
        +inf where a ray meets no obstacle piece.
    """
    b = boundary
    ux, uy = ux[:, None], uy[:, None]
    # rho * u = a + s * e  =>  rho = (a x e) / (u x e), s = (a x u) / (u x e).
    den = ux * b.ey - uy * b.ex
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = (b.ax * b.ey - b.ay * b.ex) / den
        s = (b.ax * uy - b.ay * ux) / den
    met = (s >= -EPS) & (s <= 1.0 + EPS) & (rho >= start)  # False where den = 0 (NaN, inf)
    return np.where(met, rho, np.inf).min(axis=1, initial=np.inf)


def cone_nearest(boundary: Boundary, lo: np.ndarray, hi: np.ndarray, start: float) -> np.ndarray:
    """``(c,)`` distance (m) from the body centre to the nearest obstacle in each wedge.

    Args:
        lo, hi: ``(c,)`` wedge edges from the body centre, rad; ``0 < hi - lo < pi``.
        start: the wedges begin this far from the centre (m, the mount ring); obstacles
            wholly nearer are not seen, and one that crosses it reads ``start``.

    Returns:
        +inf where no obstacle piece enters a wedge.
    """
    b = boundary
    s_lo = np.zeros((lo.size, b.ax.size))
    s_hi = np.ones((lo.size, b.ax.size))
    # Inside the wedge: left of its lo edge and right of its hi edge; each is a linear
    # condition n.a + s n.e >= 0 on the piece's parameter s.
    with np.errstate(divide="ignore", invalid="ignore"):
        for nx, ny in ((-np.sin(lo), np.cos(lo)), (np.sin(hi), -np.cos(hi))):
            na = nx[:, None] * b.ax + ny[:, None] * b.ay
            ne = nx[:, None] * b.ex + ny[:, None] * b.ey
            bound = -na / ne
            s_lo = np.where(ne > 0.0, np.maximum(s_lo, bound), s_lo)
            s_hi = np.where(ne < 0.0, np.minimum(s_hi, bound), s_hi)
            s_hi = np.where((ne == 0.0) & (na < 0.0), -1.0, s_hi)
        length2 = b.ex * b.ex + b.ey * b.ey
        foot = np.where(length2 > 0.0, -(b.ax * b.ex + b.ay * b.ey) / length2, 0.0)
    s = np.clip(foot, s_lo, s_hi)
    rho = np.hypot(b.ax + s * b.ex, b.ay + s * b.ey)
    inside = s_lo <= s_hi
    if start > 0.0:
        # The distance from the centre is largest at an end of the stretch in the wedge.
        outer = np.maximum(
            np.hypot(b.ax + s_lo * b.ex, b.ay + s_lo * b.ey),
            np.hypot(b.ax + s_hi * b.ex, b.ay + s_hi * b.ey),
        )
        inside &= outer >= start
        rho = np.maximum(rho, start)
    return np.where(inside, rho, np.inf).min(axis=1, initial=np.inf)


def in_wedges(origin: np.ndarray, points: np.ndarray, wedges: np.ndarray) -> np.ndarray:
    """``(k,)`` True where a point lies strictly inside one of the wedges.

    Args:
        origin: ``(2,)`` the wedges' apex (the scanner), m, body frame.
        points: ``(k, 2)`` points, m, body frame.
        wedges: ``(w, 2)`` wedges ``[lo, hi]`` (rad, seen from ``origin``).
    """
    psi = np.arctan2(points[:, 1] - origin[1], points[:, 0] - origin[0])[:, None]
    into = np.mod(psi - wedges[:, 0], 2.0 * np.pi)
    return ((into > EPS) & (into < wedges[:, 1] - wedges[:, 0] - EPS)).any(axis=1)


def wedge_intervals(
    origin: np.ndarray, directions: np.ndarray, wedges: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Where rays from the body centre run inside wedges seen from ``origin``.

    Args:
        origin: ``(2,)`` the wedges' apex (the scanner), m, body frame.
        directions: ``(r,)`` ray directions, rad, body frame.
        wedges: ``(w, 2)`` wedges ``[lo, hi]`` (rad), each narrower than 180 deg.

    Returns:
        ``(r, w)`` start and end (m from the centre, >= 0) of each ray's stretch inside each
        wedge; empty where start >= end.
    """
    ux, uy = np.cos(directions)[:, None], np.sin(directions)[:, None]
    sx, sy = origin
    start = np.zeros((directions.size, wedges.shape[0]))
    end = np.full_like(start, np.inf)
    for edge, sign in ((wedges[:, 0], 1.0), (wedges[:, 1], -1.0)):
        # sign * (edge x (rho u - s)) >= 0: rho * k >= c, linear in rho.
        dx, dy = np.cos(edge), np.sin(edge)
        k = sign * _cross(dx, dy, ux, uy)
        c = sign * _cross(dx, dy, sx, sy)
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = c / k
        start = np.where(k > 0.0, np.maximum(start, bound), start)
        end = np.where(k < 0.0, np.minimum(end, bound), end)
        end = np.where((k == 0.0) & (c > 0.0), -np.inf, end)
    return start, end


def stretch_inside(
    origin: np.ndarray, directions: np.ndarray, wedges: np.ndarray, near: float, far: float
) -> np.ndarray:
    """``(r,)`` length (m) of each ray's stretch inside the wedges.

    The stretch runs from ``near`` to ``far`` m from the centre; the wedges must not overlap.
    """
    if wedges.shape[0] == 0:
        return np.zeros(directions.size)
    start, end = wedge_intervals(origin, directions, wedges)
    return np.clip(np.minimum(end, far) - np.maximum(start, near), 0.0, None).sum(axis=1)
