"""The 4WS motion model against hand-computed cases (docs/design.md section 2)."""

import math

import numba
import numpy as np
import pytest

from evorbc_ros.robots.four_ws import FourWSGeometry
from evorbc_ros.robots.registry import robot_type
from sim_bridge.four_ws.motion import (
    HEADING,
    SPEED,
    STATE_SIZE,
    X,
    Y,
    motion_limits,
    step_robot,
)
from sim_bridge.geometry import wall_boxes
from sim_bridge.kinematics import run_model_primitives

G = FourWSGeometry()
LIM = motion_limits(G)
HX, HY = G.wheel_x, G.wheel_y
NO_WALLS = (np.empty((0, 6)), np.empty(0, dtype=np.int64))
DEG = math.pi / 180.0


def moving_state(angles, speed, pose=(0.0, 0.0, 0.0)):
    """A robot already at its commanded speed and wheel angles (so no rate limiting)."""
    s = np.zeros((1, STATE_SIZE))
    s[0, :3] = pose
    s[0, SPEED] = speed
    s[0, 4:] = angles
    return s, np.array([speed, *angles], dtype=np.float64)


def steps(state, command, n, walls=NO_WALLS):
    travelled = 0.0
    for _ in range(n):
        travelled += step_robot(state, 0, command, LIM, *walls)
    return travelled


def test_straight_from_rest_accelerates_then_cruises():
    # Speed ramps 0.04, 0.08, ..., 0.20 m/s (0.4 m/s^2), then holds: 0.06 m + 15 * 0.02 m.
    out = run_model_primitives(np.array([[0.2, 0, 0, 0, 0], [-0.2, 0, 0, 0, 0]], float), 20, LIM)
    np.testing.assert_allclose(out[0], [0.36, 0.0, 0.0, 0.36], atol=1e-12)
    np.testing.assert_allclose(out[1], [-0.36, 0.0, 0.0, 0.36], atol=1e-12)


def test_crab_motion_from_rest_follows_the_ramping_wheels():
    a = 30 * DEG
    out = run_model_primitives(np.array([[0.2, a, a, a, a]]), 20, LIM)[0]
    # Angles ramp 9, 18, 27, 30 deg while the speed ramps; all wheels stay parallel.
    legs = [(0.004, 9), (0.008, 18), (0.012, 27), (0.016 + 15 * 0.02 + 0.02, 30)]
    x = sum(s * math.cos(d * DEG) for s, d in legs)
    y = sum(s * math.sin(d * DEG) for s, d in legs)
    np.testing.assert_allclose(out, [x, y, 0.0, 0.36], atol=1e-12)


def test_crab_motion_within_one_degree_uses_the_mean_direction():
    angles = np.array([30.0, 30.8, 30.4, 30.2]) * DEG
    state, cmd = moving_state(angles, 0.1, pose=(1.0, 2.0, 0.3))
    assert steps(state, cmd, 1) == pytest.approx(0.01)
    direction = 0.3 + angles.mean()
    np.testing.assert_allclose(
        state[0, :3],
        [1 + 0.01 * math.cos(direction), 2 + 0.01 * math.sin(direction), 0.3],
        atol=1e-15,
    )


@pytest.mark.parametrize("speed", [0.1, -0.1])
@pytest.mark.parametrize("side", [1.0, -1.0])
def test_ackermann_arc_with_fixed_rear_wheels(speed, side):
    # Front wheels aimed so their axles meet the rear axle line at ICR (-hx, side * R):
    # zero slip everywhere. The centre then circles the ICR at radius sqrt(hx^2 + R^2).
    R = 0.2
    a_fl = math.atan2(2 * HX, side * R - HY)
    a_fr = math.atan2(2 * HX, side * R + HY)
    a_fl, a_fr = (math.remainder(a, math.pi) for a in (a_fl, a_fr))
    pose = (1.0, -0.5, 0.7)
    state, cmd = moving_state([a_fl, a_fr, 0.0, 0.0], speed, pose)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    icr = np.array([pose[0] + c * -HX - s * side * R, pose[1] + s * -HX + c * side * R])
    radius = math.hypot(HX, R)
    n = 30
    travelled = steps(state, cmd, n)
    turn = side * math.copysign(1, speed) * n * abs(speed) * LIM.dt / radius
    assert travelled == pytest.approx(n * abs(speed) * LIM.dt, abs=1e-12)
    assert state[0, HEADING] - pose[2] == pytest.approx(turn, abs=1e-12)
    start = np.array(pose[:2]) - icr
    rot = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    np.testing.assert_allclose(state[0, [X, Y]], icr + rot @ start, atol=1e-12)
    assert math.dist(state[0, [X, Y]], icr) == pytest.approx(radius, abs=1e-12)


def test_symmetric_four_wheel_ackermann_turns_about_a_point_abeam_the_centre():
    # ICR at (0, R): front wheels toe in, rear wheels mirror them (4ws-5 only).
    R = 0.15
    a_f_left = math.atan2(HX, R - HY)
    a_f_right = math.atan2(HX, R + HY)
    angles = [a_f_left, a_f_right, -a_f_left, -a_f_right]
    state, cmd = moving_state(angles, 0.2)
    steps(state, cmd, 10)
    turn = 10 * 0.02 / R
    np.testing.assert_allclose(
        state[0, :3], [R * math.sin(turn), R * (1 - math.cos(turn)), turn], atol=1e-12
    )


def test_more_than_ten_degrees_of_slip_means_no_motion():
    # 2ws-2 with both fronts at 45 deg: ICR = (-hx, 0.05 cot 45) = (-0.025, 0.05); the
    # front-left wheel then slips atan2(0.025, 0.05) - 45 deg... = 18.4 deg > 10 deg.
    state, cmd = moving_state([45 * DEG, 45 * DEG, 0, 0], 0.2, pose=(0.3, 0.4, 0.5))
    assert steps(state, cmd, 5) == 0.0
    np.testing.assert_array_equal(state[0, :3], [0.3, 0.4, 0.5])
    # At 30 deg the slips are 9.1 and 5.9 deg: the robot moves.
    state, cmd = moving_state([30 * DEG, 30 * DEG, 0, 0], 0.2)
    assert steps(state, cmd, 1) == pytest.approx(0.02)
    assert state[0, HEADING] > 0


def test_icr_inside_the_wheel_rectangle_means_no_motion():
    # Wheels tangent to a circle around the centre: ICR = (0, 0). One shared wheel speed
    # cannot spin the body on the spot.
    a = 45 * DEG
    state, cmd = moving_state([-a, a, a, -a], 0.2)
    assert steps(state, cmd, 3) == 0.0
    np.testing.assert_array_equal(state[0, :3], [0, 0, 0])


def test_rate_limits_on_wheel_angles_and_speed():
    state = np.zeros((1, STATE_SIZE))
    cmd = np.array([5.0, 45 * DEG, -45 * DEG, 30 * DEG, -10 * DEG])  # speed beyond range
    step_robot(state, 0, cmd, LIM, *NO_WALLS)
    np.testing.assert_allclose(state[0, SPEED], 0.04, atol=1e-15)
    np.testing.assert_allclose(state[0, 4:], np.array([9, -9, 9, -9]) * DEG, atol=1e-15)
    for _ in range(3):
        step_robot(state, 0, cmd, LIM, *NO_WALLS)
    np.testing.assert_allclose(state[0, 4:], np.array([36, -36, 30, -10]) * DEG, atol=1e-14)
    step_robot(state, 0, cmd, LIM, *NO_WALLS)
    np.testing.assert_allclose(state[0, 4:], np.array([45, -45, 30, -10]) * DEG, atol=1e-14)
    np.testing.assert_allclose(state[0, SPEED], 0.2, atol=1e-15)  # clipped to 0.2 m/s
    cmd = np.array([-0.2, 0.0, 0.0, 0.0, 0.0])
    step_robot(state, 0, cmd, LIM, *NO_WALLS)
    np.testing.assert_allclose(state[0, SPEED], 0.16, atol=1e-15)


def test_wall_contact_stops_the_body_but_keeps_the_heading_change():
    # A wall along x = 0.2 m, 1 cm thick.
    wall = (wall_boxes(np.array([[0.2, -1.0, 0.2, 1.0]]), 0.01), np.array([0]))
    state, cmd = moving_state([0, 0, 0, 0], 0.1, pose=(0.13, 0.0, 0.0))
    assert steps(state, cmd, 1, wall) == pytest.approx(0.01)  # 0.055 m clearance: free
    assert steps(state, cmd, 1, wall) == 0.0  # would leave 0.045 m < 0.05 m: blocked
    np.testing.assert_allclose(state[0, :3], [0.14, 0.0, 0.0], atol=1e-15)
    # Turning into the wall: the position stays, the heading still changes.
    R = 0.2
    a_fl, a_fr = math.atan2(2 * HX, R - HY), math.atan2(2 * HX, R + HY)
    state, cmd = moving_state([a_fl, a_fr, 0, 0], 0.1, pose=(0.14, 0.0, 0.0))
    assert steps(state, cmd, 1, wall) == 0.0
    assert state[0, X] == 0.14 and state[0, Y] == 0.0
    assert state[0, HEADING] == pytest.approx(0.01 / math.hypot(HX, R), abs=1e-12)


def test_primitives_do_not_depend_on_the_number_of_threads():
    rng = np.random.default_rng(3)
    cmds = robot_type("4ws-5").commands(rng.uniform(-1, 1, (2000, 5)), G)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = run_model_primitives(cmds, 20, LIM)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = run_model_primitives(cmds, 20, LIM)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one, many)


@pytest.mark.parametrize(
    ("name", "genes", "expected"),
    [
        ("2ws-2", [1, 0.5], [0.2, 22.5, 22.5, 0, 0]),
        ("2ws-3", [-1, 0.5, -1], [-0.2, 22.5, -45, 0, 0]),
        ("4ws-3", [0.5, 1, -1], [0.1, 45, 45, -45, -45]),
        ("4ws-5", [0, 0.2, 0.4, 0.6, -0.8], [0, 9, 18, 27, -36]),
    ],
)
def test_robot_types_map_genes_onto_wheel_commands(name, genes, expected):
    cmd = robot_type(name).commands(np.array(genes, float), G)
    np.testing.assert_allclose(cmd, np.array(expected) * [1, DEG, DEG, DEG, DEG], atol=1e-15)
