"""A scanner anywhere on the body: each rangefinder reads what a ray cast from its own
mount point reads (issue 18, item 1), checked against an independent ray cast."""

import math

import numpy as np
import pytest
from laser_scenes import box, cast, post, ray_distances, scan, true_distances, true_readings, wall

from evorbc_ros.config import config_dir
from evorbc_ros.laser import InputError, LaserPose, LaserToRangefinders
from evorbc_ros.scan_geometry import GRAZING_ANGLE
from evorbc_ros.sensors import SensorLayout

LAYOUTS = {
    name: SensorLayout.load(config_dir() / "sensors" / f"{name}.yaml").rangefinders
    for name in ("4ws", "hexapod")
}
RF = LAYOUTS["4ws"]
DEG = math.pi / 180
#: Scanner poses: offsets up to 0.1 m in x and y, yaws including 90 and 180 deg.
POSES = [
    LaserPose(0.0, 0.1, 0.0),  # the issue's reproduction
    LaserPose(0.1, 0.0, 0.0),  # on the forward axis: the 0 deg ray runs through the scanner
    LaserPose(-0.07, 0.05, 90 * DEG),
    LaserPose(0.05, -0.1, 180 * DEG),
    LaserPose(0.1, 0.1, -45 * DEG),
    LaserPose(-0.1, -0.1, 30 * DEG),
    LaserPose(-0.1, 0.0, 180 * DEG),
]
#: Walls 0.15 to 2.1 m from the centre in front, behind and to each side (the 4WS
#: rangefinders reach 1.05 m from the centre, the hexapod's 2 m); a room; posts in a room.
SCENES = {f"{side} {d}": wall(side, d) for side in ("front", "behind", "left", "right")
          for d in (0.15, 0.3, 0.5, 0.8, 1.2, 2.1)}  # fmt: skip
SCENES["room"] = box(-0.4, -0.5, 0.6, 0.35)
SCENES["post ahead"] = np.concatenate([box(-1.5, -1.2, 1.3, 1.4), post(0.35, 0.15, 0.04, 0.5)])
SCENES["post behind"] = np.concatenate([box(-1.5, -1.2, 1.3, 1.4), post(-0.3, -0.25, 0.06, 0.2)])
RANGE_MAX = 8.0  # m, the scanner's


def visible(pose, points, segments):
    """Which ``(k, 2)`` points the scanner at ``pose`` sees (no wall in between)."""
    v = points - [pose.x, pose.y]
    dist = np.hypot(v[:, 0], v[:, 1])
    d = cast(np.full(len(v), pose.x), np.full(len(v), pose.y), v[:, 0] / dist, v[:, 1] / dist,
             segments)  # fmt: skip
    return d >= dist - 1e-9


def hidden_from_scanner(layout, pose, segments):
    """``(n_rangefinders,)`` True where part of a rangefinder's rays, up to what they hit
    (or their range), is hidden from the scanner: the scan does not cover it there."""
    half = 0.5 * layout.field_of_view
    offsets = np.linspace(-half, half, 61) if half else np.zeros(1)
    d = ray_distances(layout, segments, offsets)
    m = layout.mount_radius
    out = []
    for k, axis in enumerate(layout.angles):
        a = axis + offsets[:, None]
        t = m + np.linspace(0.0, 1.0, 200)[None, :] * (
            np.minimum(d[k], layout.max_range)[:, None] - 1e-6
        )
        pts = np.stack([(t * np.cos(a)).ravel(), (t * np.sin(a)).ravel()], axis=1)
        out.append(not visible(pose, pts, segments).all())
    return np.array(out)


def resolution(layout, pose, segments, n):
    """``(n_rangefinders,)`` how precisely the scan pins down what each rangefinder reads.

    0 where the nearest point a rangefinder sees lies inside a wall face that both scanner
    beams around it hit, seen more steeply than the breakpoint rule's grazing angle (plus
    1 deg): the rebuilt surface there is the wall itself. Elsewhere (a corner, an edge, a
    grazing view) the scan only knows the wall at its beams: the distance between the hits
    of the two beams around that point (m).
    """
    d = true_distances(layout, segments)
    m = layout.mount_radius
    out = np.zeros(len(d))
    for k, axis in enumerate(layout.angles):
        if not d[k] < layout.max_range:
            continue  # nothing within range: the rebuilt view must be empty there too
        h = nearest_point(layout, axis, d[k] + m, segments)
        seg = on_segment(h, segments)
        psi = math.atan2(h[1] - pose.y, h[0] - pose.x) - pose.yaw
        inc = 2 * math.pi / n
        lo = math.floor((psi + math.pi) / inc)
        beams = -math.pi + inc * np.array([lo, lo + 1]) + pose.yaw
        hits = cast([pose.x] * 2, [pose.y] * 2, np.cos(beams), np.sin(beams), segments)
        p = np.stack([pose.x + hits * np.cos(beams), pose.y + hits * np.sin(beams)], axis=1)
        same_face = all(on_segment(q, segments) == seg for q in p)
        x0, y0, x1, y1 = segments[seg]
        view = abs(
            math.remainder(
                math.atan2(y1 - y0, x1 - x0) - math.atan2(*(h - [pose.x, pose.y])[::-1]), math.pi
            )
        )
        end = min(np.hypot(*(h - [x0, y0])), np.hypot(*(h - [x1, y1])))
        if not (same_face and min(view, math.pi - view) > GRAZING_ANGLE + DEG and end > 1e-6):
            out[k] = np.hypot(*(p[1] - p[0]))
    return out


def nearest_point(layout, axis, rho, segments):
    """The point at ``rho`` m from the centre that a rangefinder reads (its axis, or for a
    field of view, the direction in it whose ray meets a wall there)."""
    half = 0.5 * layout.field_of_view
    a = axis + (np.linspace(-half, half, 20001) if half else np.zeros(1))
    pts = np.stack([rho * np.cos(a), rho * np.sin(a)], axis=1)
    return pts[int(np.argmin(point_to_segments(pts, segments).min(axis=1)))]


def point_to_segments(p, segments):
    """``(k, s)`` distance (m) from each of ``(k, 2)`` points to each segment."""
    p = np.atleast_2d(p)[:, :, None]
    x0, y0, x1, y1 = segments.T
    wx, wy = x1 - x0, y1 - y0
    s = np.clip(((p[:, 0] - x0) * wx + (p[:, 1] - y0) * wy) / (wx * wx + wy * wy), 0, 1)
    return np.hypot(x0 + s * wx - p[:, 0], y0 + s * wy - p[:, 1])


def on_segment(p, segments):
    return int(np.argmin(point_to_segments(p, segments)[0]))


@pytest.mark.parametrize("n", [360, 720])
@pytest.mark.parametrize(
    "pose", POSES, ids=lambda p: f"{p.x:+.2f},{p.y:+.2f},{math.degrees(p.yaw):.0f}"
)
def test_offset_scanner_reads_what_rays_from_the_mount_points_read(pose, n):
    exact = loose = hidden = 0
    for name, layout in LAYOUTS.items():
        converter = LaserToRangefinders(layout, pose)
        for scene, segments in SCENES.items():
            angle_min, inc, ranges = scan(pose, segments, n, RANGE_MAX)
            got = converter.readings(angle_min, inc, ranges, 0.0, RANGE_MAX)
            want = true_readings(layout, segments)
            covered = ~hidden_from_scanner(layout, pose, segments)
            where = f"{name}, {scene}"
            # Behind an obstacle (as the scanner sees it) the rebuilt view has a shadow edge:
            # the reading may be nearer than the truth there, never farther.
            assert np.all(got[~covered] >= want[~covered] - 1e-9), where
            hidden += int((~covered).sum())
            # Where the scan covers the ray: the wall itself, to rounding (1e-9 of the
            # range), or within the scan's own sample spacing at a corner, an edge or a
            # grazing view.
            res = resolution(layout, pose, segments, n) / layout.max_range
            tol = np.where(res > 0, res, 1e-9)
            np.testing.assert_array_less(np.abs(got - want)[covered], tol[covered] + 1e-12, where)
            exact += int((covered & (res == 0)).sum())
            loose += int((covered & (res > 0)).sum())
    assert exact >= 0.97 * (exact + loose)  # most checks are to rounding
    assert hidden <= 0.02 * (exact + loose + hidden)


def test_the_issue_reproduction():
    # 720 beams from -pi; scanner at laser_y = 0.1 m; a wall 0.38 m ahead of the scanner.
    segments = wall("front", 0.38)
    for pose in (LaserPose(0.0, 0.1), LaserPose()):
        angle_min, inc, ranges = scan(pose, segments, 720, RANGE_MAX)
        got = LaserToRangefinders(RF, pose).readings(angle_min, inc, ranges, 0.0, RANGE_MAX)
        # The front rangefinder, 0.05 m from the centre, is 0.33 m from the wall: 1 - 0.33.
        assert got[0] == pytest.approx(0.67, abs=1e-12), pose  # it read 0.000 before
        np.testing.assert_allclose(got, true_readings(RF, segments), atol=1e-12)


@pytest.mark.parametrize("n", [360, 720, 1440])
def test_a_tiny_offset_reads_like_the_centred_scanner(n):
    # The centred rule takes the beam on each ray; the offset rule rebuilds the walls and
    # casts the rays into them: for a scanner 1 micrometre off the centre they agree.
    # (Fields of view differ more: the centred rule sees a cone only at its beams.)
    segments = box(-0.4, -0.5, 0.6, 0.35)
    angle_min, inc, ranges = scan(LaserPose(), segments, n, RANGE_MAX)
    centred = LaserToRangefinders(RF).readings(angle_min, inc, ranges, 0.0, RANGE_MAX)
    tiny = LaserPose(1e-6, -1e-6)
    angle_min, inc, ranges = scan(tiny, segments, n, RANGE_MAX)
    offset = LaserToRangefinders(RF, tiny).readings(angle_min, inc, ranges, 0.0, RANGE_MAX)
    np.testing.assert_allclose(offset, centred, atol=3e-6)  # 1.4e-6 m of offset, and rounding


def test_float32_ranges_and_decreasing_increments():
    pose = LaserPose(0.08, -0.06, 120 * DEG)
    segments = box(-0.4, -0.5, 0.6, 0.35)
    angle_min, inc, ranges = scan(pose, segments, 720, RANGE_MAX)
    want = true_readings(RF, segments)
    converter = LaserToRangefinders(RF, pose)
    got = converter.readings(
        np.float32(angle_min), np.float32(inc), ranges.astype(np.float32), 0.0, RANGE_MAX
    )
    np.testing.assert_allclose(got, want, atol=1e-6)  # float32: 6e-8 of 0.5 m, and the angles
    last = angle_min + inc * 719
    got = converter.readings(last, -inc, ranges[::-1], 0.0, RANGE_MAX)
    np.testing.assert_allclose(got, want, atol=1e-9)


def partial_scan(pose, segments, lo_deg, hi_deg, step_deg=0.5):
    """A scan from ``lo_deg`` to ``hi_deg`` (scanner frame)."""
    beams = np.radians(np.arange(lo_deg, hi_deg + step_deg / 2, step_deg))
    a = beams + pose.yaw
    r = cast(np.full(a.size, pose.x), np.full(a.size, pose.y), np.cos(a), np.sin(a), segments)
    return beams[0], math.radians(step_deg), np.where(r <= RANGE_MAX, r, np.inf)


def test_a_partial_scan_from_an_offset_scanner_covers_some_rays_partly():
    # A 180-deg scanner 0.1 m ahead of the centre, facing forward, in a room: it sees
    # nothing behind itself, so the rays at 120 to 240 deg are never covered; the 0 deg ray
    # starts 0.05 m behind it, and the 60 and 300 deg rays start behind it too.
    pose = LaserPose(0.1, 0.0)
    segments = box(-0.4, -0.5, 0.6, 0.35)
    converter = LaserToRangefinders(RF, pose)
    angle_min, inc, ranges = partial_scan(pose, segments, -90.0, 90.0)
    cover = converter.coverage(angle_min, inc, ranges.size)
    assert cover.unseen == [120.0, 180.0, 240.0]
    # The 60 deg ray leaves the mount at (0.025, 0.043) m and enters the span 0.1485 m
    # along, where it crosses the span's edge (the last beam, 90 deg, plus half a spacing).
    assert cover.partly == pytest.approx({0.0: 0.95, 60.0: 0.8515, 300.0: 0.8515}, abs=1e-3)
    got = converter.readings(angle_min, inc, ranges, 0.0, RANGE_MAX)
    want = true_readings(RF, segments)
    np.testing.assert_allclose(
        got[[0, 1, 5]], want[[0, 1, 5]], atol=1e-9
    )  # walls in the covered part
    np.testing.assert_array_equal(got[[2, 3, 4]], 0.0)  # unseen: nothing seen


def test_a_post_in_the_uncovered_start_of_a_ray_is_not_seen():
    # Documented behaviour: the part of a ray outside the scan's span reads nothing seen.
    pose = LaserPose(0.1, 0.0)
    segments = post(
        0.06, 0.09, 0.01, 0.0
    )  # on the 60 deg ray, 0.05-0.07 m along, behind the scanner
    angle_min, inc, ranges = partial_scan(pose, segments, -90.0, 90.0)
    got = LaserToRangefinders(RF, pose).readings(angle_min, inc, ranges, 0.0, RANGE_MAX)
    assert got[1] == 0.0 and true_readings(RF, segments)[1] > 0.9


def test_dropouts_with_an_offset_scanner():
    pose = LaserPose(0.0, 0.1)
    segments = box(-0.4, -0.5, 0.6, 0.35)
    angle_min, inc, ranges = scan(pose, segments, 360, RANGE_MAX)
    converter = LaserToRangefinders(RF, pose)
    clean = converter.readings(angle_min, inc, ranges, 0.0, RANGE_MAX)
    rng = np.random.default_rng(3)
    used = 0
    for _ in range(200):
        r = ranges.copy()
        r[rng.random(r.size) < 0.05] = math.nan
        try:
            got = converter.readings(angle_min, inc, r, 0.0, RANGE_MAX)
        except InputError:
            continue
        used += 1
        np.testing.assert_allclose(got, clean, atol=1e-9)  # walls are bridged straight
    assert used >= 198
    # The 0 deg ray runs from -63 deg (its mount point) to -9.5 deg (the wall it meets at
    # x = 0.6 m) as the scanner sees it. A 20-deg dead sector that it only crosses on its
    # way changes nothing; one around the point it reads blinds it.
    heading = angle_min + inc * np.arange(360)
    r = np.where(np.abs(heading + 40 * DEG) < 10 * DEG, math.nan, ranges)
    np.testing.assert_array_equal(converter.readings(angle_min, inc, r, 0.0, RANGE_MAX), clean)
    r = np.where(np.abs(heading + 9.5 * DEG) < 10 * DEG, math.nan, ranges)
    with pytest.raises(InputError, match=r"rangefinder at 0\.0 deg"):
        converter.readings(angle_min, inc, r, 0.0, RANGE_MAX)


def test_touching_the_scanner_blocks_the_rays_that_pass_it():
    # REP 117: -inf is an object closer than range_min. The scanner sits 0.1 m ahead on the
    # forward axis; the 0 deg ray, from 0.05 m, passes through it.
    pose = LaserPose(0.1, 0.0)
    angle_min, inc, ranges = scan(pose, box(-0.4, -0.5, 0.6, 0.35), 360, RANGE_MAX)
    converter = LaserToRangefinders(RF, pose)
    clean = converter.readings(angle_min, inc, ranges, 0.0, RANGE_MAX)
    ranges[180] = -math.inf  # the beam at 0 deg
    got = converter.readings(angle_min, inc, ranges, 0.0, RANGE_MAX)
    assert got[0] == pytest.approx(1 - 0.05, abs=1e-12)  # met at the scanner, 0.05 m out
    np.testing.assert_array_equal(got[1:], clean[1:])
