"""A scanner at the body centre with every beam valid reads bit for bit as before issue 18.

The hexapod's offline episodes and the lockstep parity tests depend on these exact bits; the
reference is the code before the change, kept in ``tests/reference_laser.py``.
"""

import math

import numpy as np
import pytest
from reference_laser import OldLaserToRangefinders

from evorbc_ros.config import config_dir
from evorbc_ros.laser import LaserPose, LaserToRangefinders
from evorbc_ros.sensors import SensorLayout
from sim_bridge.legged.scanner import Scanner

LAYOUTS = {
    name: SensorLayout.load(config_dir() / "sensors" / f"{name}.yaml").rangefinders
    for name in ("4ws", "hexapod")
}
YAWS_DEG = [0.0, 0.3, 45.0, 90.0, 180.0, -137.0]


def random_ranges(rng, n, range_min, range_max):
    """Valid ranges: hits, no returns (+inf, beyond range_max), touching (-inf), range_min."""
    r = rng.uniform(range_min, 2.5, n)
    special = rng.random(n)
    r[special < 0.05] = math.inf
    r[(special >= 0.05) & (special < 0.08)] = range_max + rng.uniform(0.0, 5.0)
    r[(special >= 0.08) & (special < 0.09)] = -math.inf
    r[(special >= 0.09) & (special < 0.10)] = range_min
    if rng.random() < 0.5:
        r = r.astype(np.float32)  # as a LaserScan carries them
        # float32(range_min) can round below range_min, which would make the beam invalid.
        r[np.isfinite(r) & (r < range_min)] = np.nextafter(np.float32(range_min), np.inf)
    return r


def spans(rng):
    """Full turns, the bridge's and the hexapod's spans, and random partial spans."""
    yield -math.pi, 2 * math.pi / 360, 360
    yield -math.pi, 2 * math.pi / 720, 720
    yield float(np.float32(math.pi)), float(np.float32(-2 * math.pi / 1440)), 1440
    hexapod = Scanner.from_layout(LAYOUTS["hexapod"])
    yield hexapod.angle_min, hexapod.angle_increment, hexapod.beams
    for _ in range(4):
        n = int(rng.integers(25, 900))
        inc = float(np.float32(rng.uniform(0.1, 1.0) * math.pi / 180))
        sign = rng.choice([-1.0, 1.0])
        yield float(np.float32(rng.uniform(-math.pi, math.pi))), sign * inc, n


@pytest.mark.parametrize("layout", LAYOUTS, ids=LAYOUTS)
@pytest.mark.parametrize("yaw_deg", YAWS_DEG)
def test_centred_clean_scans_read_exactly_as_before(layout, yaw_deg):
    rng = np.random.default_rng(int(yaw_deg * 10) % 1000 + len(layout))
    pose = LaserPose(yaw=math.radians(yaw_deg))
    new = LaserToRangefinders(LAYOUTS[layout], pose)
    old = OldLaserToRangefinders(LAYOUTS[layout], pose)
    checked = 0
    for angle_min, inc, n in spans(rng):
        for _ in range(6):
            range_min, range_max = rng.choice([0.0, 0.02, 0.1]), rng.choice([2.0, 3.5, 12.0])
            r = random_ranges(rng, n, range_min, range_max)
            want = old.readings(angle_min, inc, r, range_min, range_max)
            got = new.readings(angle_min, inc, r, range_min, range_max)
            np.testing.assert_array_equal(got, want)  # bit for bit, not approximately
            checked += 1
        assert new.unseen(angle_min, inc, n) == old.unseen(angle_min, inc, n)
    assert checked == 48


def test_the_hexapod_scanner_reads_exactly_as_before():
    # The offline hexapod episode's call: float32 ranges of its 25-beam scanner.
    layout = LAYOUTS["hexapod"]
    s = Scanner.from_layout(layout)
    rng = np.random.default_rng(5)
    new, old = LaserToRangefinders(layout), OldLaserToRangefinders(layout)
    for _ in range(500):
        r = rng.uniform(0.05, 2.4, s.beams).astype(np.float32)
        r[rng.random(s.beams) < 0.2] = np.inf
        args = (s.angle_min, s.angle_increment, r, s.range_min, s.range_max)
        np.testing.assert_array_equal(new.readings(*args), old.readings(*args))
