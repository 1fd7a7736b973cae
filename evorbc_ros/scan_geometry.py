"""What an off-centre scanner saw, as geometry in the body frame (docs/laser.md).

A rangefinder of the sensor layout is a set of rays from the body centre that start at the
mount ring (``mount_radius``), as the offline simulator casts them (DESIGN.md section 5).
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
obstacle point inside its wedge. A ray that enters an unknown wedge before its first hit
(and within its range) is blind. Parts of a ray outside the scan's span see nothing.

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
        angle, cos, sin: ``(n,)`` beam directions in the body frame, rad, increasing.
        spacing: angle between neighbouring beams, rad (> 0).
        closed: the beams go round the whole circle, so the last neighbours the first.
        lo, hi: edges of the span (rad), half a spacing beyond the outer beams.
    """

    origin: np.ndarray
    index: np.ndarray
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
        a, b: ``(p, 2)`` end points of the obstacle pieces, m, body frame.
        unknown: ``(w, 2)`` wedges ``[lo, hi]`` (rad, seen from the scanner, each narrower
            than 90 deg) holding no valid beam within the tolerance.
    """

    a: np.ndarray
    b: np.ndarray
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


def build_boundary(beams: ScanBeams, kind: np.ndarray, r: np.ndarray, tolerance: float) -> Boundary:
    """The obstacle pieces and unknown wedges of a scan.

    Args:
        beams: the scan's geometry.
        kind, r: ``(n,)`` message-order beam kinds and ranges from :func:`classify`.
        tolerance: how far (rad) a valid beam's view reaches over invalid neighbours.
    """
    kind = kind[beams.index]
    valid = np.flatnonzero(kind != INVALID)
    sx, sy = beams.origin
    if valid.size == 0:
        everything = [beams.lo, beams.lo + 2.0 * math.pi] if beams.closed else [beams.lo, beams.hi]
        return Boundary(np.empty((0, 2)), np.empty((0, 2)), split_wedges(np.array([everything])))
    kind = kind[valid]
    rv = r[beams.index][valid]
    psi = beams.angle[valid]
    px = sx + rv * beams.cos[valid]
    py = sy + rv * beams.sin[valid]
    solid = kind != OPEN  # hits and touching: obstacles at their end point

    # Neighbouring valid beams (i, j), counter-clockwise; the gap between them (rad).
    i = np.arange(valid.size - 1)
    j = i + 1
    gap = (valid[j] - valid[i]) * beams.spacing
    if beams.closed:
        i = np.append(i, valid.size - 1)
        j = np.append(j, 0)
        gap = np.append(gap, 2.0 * math.pi - (valid[-1] - valid[0]) * beams.spacing)
    bridged = gap <= 2.0 * tolerance + 1e-9
    near = np.minimum(rv[i], rv[j])
    apart = np.hypot(px[j] - px[i], py[j] - py[i])
    # Adaptive breakpoint distance; no surface can be inferred across a gap >= the angle.
    with np.errstate(divide="ignore", invalid="ignore"):
        reach = near * np.sin(gap) / np.sin(GRAZING_ANGLE - gap) + 3.0 * RANGE_SIGMA
    surface = bridged & solid[i] & solid[j] & (gap < GRAZING_ANGLE) & (apart <= reach)

    a = [np.stack([px[i[surface]], py[i[surface]]], axis=1)]
    b = [np.stack([px[j[surface]], py[j[surface]]], axis=1)]
    rest = ~surface & ~(bridged & ~solid[i] & ~solid[j])
    i, j, gap, bridged = i[rest], j[rest], gap[rest], bridged[rest]
    # Each side keeps its range over its half of the gap, or over the tolerance.
    half = np.where(bridged, 0.5 * gap, tolerance)
    ei = psi[i] + half  # end of beam i's piece
    ej = psi[i] + gap - half  # start of beam j's piece
    cix, ciy = sx + rv[i] * np.cos(ei), sy + rv[i] * np.sin(ei)
    cjx, cjy = sx + rv[j] * np.cos(ej), sy + rv[j] * np.sin(ej)
    for keep, (ax, ay, bx, by) in (
        (solid[i], (px[i], py[i], cix, ciy)),  # beam i's range held
        (solid[j], (cjx, cjy, px[j], py[j])),  # beam j's range held
        (bridged, (cix, ciy, cjx, cjy)),  # the radial shadow edge at mid-gap
    ):
        a.append(np.stack([ax[keep], ay[keep]], axis=1))
        b.append(np.stack([bx[keep], by[keep]], axis=1))
    unknown = [np.stack([ei[~bridged], ej[~bridged]], axis=1)]

    if not beams.closed:
        # The outer valid beams reach to the span's edges, or over the tolerance.
        for k, edge, sign in ((0, beams.lo, -1.0), (valid.size - 1, beams.hi, 1.0)):
            held = psi[k] + sign * min(tolerance, abs(psi[k] - edge))
            if solid[k]:
                a.append(np.array([[px[k], py[k]]]))
                b.append(np.array([[sx + rv[k] * math.cos(held), sy + rv[k] * math.sin(held)]]))
            if abs(psi[k] - edge) > tolerance:
                unknown.append(np.array([sorted((held, edge))]))
    return Boundary(np.concatenate(a), np.concatenate(b), split_wedges(np.concatenate(unknown)))


def ray_hits(boundary: Boundary, directions: np.ndarray) -> np.ndarray:
    """``(r,)`` distance (m) from the body centre to the first obstacle along each ray.

    Args:
        directions: ``(r,)`` ray directions (rad, body frame); rays start at the centre.

    Returns:
        +inf where a ray meets no obstacle piece.
    """
    ux, uy = np.cos(directions)[:, None], np.sin(directions)[:, None]
    ax, ay = boundary.a[:, 0], boundary.a[:, 1]
    ex, ey = boundary.b[:, 0] - ax, boundary.b[:, 1] - ay
    # rho * u = a + s * e  =>  rho = (a x e) / (u x e), s = (a x u) / (u x e).
    den = _cross(ux, uy, ex, ey)
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = _cross(ax, ay, ex, ey) / den
        s = _cross(ax, ay, ux, uy) / den
    met = (den != 0.0) & (s >= -EPS) & (s <= 1.0 + EPS) & (rho >= 0.0)
    return np.where(met, rho, np.inf).min(axis=1, initial=np.inf)


def cone_nearest(boundary: Boundary, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``(c,)`` distance (m) from the body centre to the nearest obstacle in each wedge.

    Args:
        lo, hi: ``(c,)`` wedge edges from the body centre, rad; ``0 < hi - lo < pi``.

    Returns:
        +inf where no obstacle piece enters a wedge.
    """
    ax, ay = boundary.a[:, 0], boundary.a[:, 1]
    ex, ey = boundary.b[:, 0] - ax, boundary.b[:, 1] - ay
    s_lo = np.zeros((lo.size, ax.size))
    s_hi = np.ones((lo.size, ax.size))
    # Inside the wedge: left of its lo edge and right of its hi edge; each is a linear
    # condition n.a + s n.e >= 0 on the piece's parameter s.
    for nx, ny in ((-np.sin(lo), np.cos(lo)), (np.sin(hi), -np.cos(hi))):
        na = nx[:, None] * ax + ny[:, None] * ay
        ne = nx[:, None] * ex + ny[:, None] * ey
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = -na / ne
        s_lo = np.where(ne > 0.0, np.maximum(s_lo, bound), s_lo)
        s_hi = np.where(ne < 0.0, np.minimum(s_hi, bound), s_hi)
        s_hi = np.where((ne == 0.0) & (na < 0.0), -1.0, s_hi)
    length2 = ex * ex + ey * ey
    with np.errstate(divide="ignore", invalid="ignore"):
        foot = np.where(length2 > 0.0, -(ax * ex + ay * ey) / length2, 0.0)
    s = np.clip(foot, s_lo, s_hi)
    rho = np.hypot(ax + s * ex, ay + s * ey)
    return np.where(s_lo <= s_hi, rho, np.inf).min(axis=1, initial=np.inf)


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
    origin: np.ndarray, directions: np.ndarray, wedges: np.ndarray, near: float, far: np.ndarray
) -> np.ndarray:
    """``(r,)`` length (m) of each ray's stretch ``[near, far]`` that lies in the wedges.

    The wedges must not overlap. ``far`` is ``(r,)`` (m from the centre).
    """
    if wedges.shape[0] == 0:
        return np.zeros(directions.size)
    start, end = wedge_intervals(origin, directions, wedges)
    start = np.maximum(start, near)
    end = np.minimum(end, np.asarray(far, dtype=np.float64)[:, None])
    return np.clip(end - start, 0.0, None).sum(axis=1)
