"""The hexapod: URDF, servos, primitives (eq. 10-11), resets, determinism and tilt."""

import functools
import math

import numpy as np
import pybullet as p
import pytest

from evorbc_ros.robots.hexapod import (
    JOINT_NAMES,
    N_PARAMETERS,
    GaitTable,
    HexapodGeometry,
    mirror_genes,
    parameter_specs,
)
from offline_evolution.quality import circular_tilt_quality
from sim_bridge.geometry import wall_boxes
from sim_bridge.hexapod.physics import HexapodSim, PhysicsSettings
from sim_bridge.hexapod.robot import DISCARD_TILT, HexapodRobot
from sim_bridge.legged.evaluate import HEADING, SECONDS, TILT, X, Y, evaluate_genes
from sim_bridge.legged.pool import EvaluationPool
from sim_bridge.legged.scanner import Scanner

G = HexapodGeometry()


@pytest.fixture(scope="module")
def sim():
    s = HexapodSim()
    yield s
    s.close()


def tripod(amp_a=1.0, amp_b=0.3, lift_phase=0.75):
    """A tripod gait: legs lf, lr, rm swing with phase 0, lm, rf, rr half a cycle later."""
    genes = [0.0]
    for leg in range(6):
        phase = 0.0 if leg in (0, 2, 4) else 0.5
        genes += [0.0, 2 * amp_a - 1, 2 * phase - 1]  # A: offset 0, amplitude, phase
        genes += [0.0, 2 * amp_b - 1, 2 * ((phase + lift_phase) % 1) - 1]  # B
    return np.array(genes)


def test_urdf_has_the_papers_joints_limits_and_a_realistic_mass(sim):
    c, robot = sim.client, sim.robot
    names = [p.getJointInfo(robot, j, physicsClientId=c)[1].decode() for j in sim.joints]
    assert names == list(JOINT_NAMES) and len(names) == 18
    limits = [p.getJointInfo(robot, j, physicsClientId=c)[8:10] for j in sim.joints]
    for k in range(6):
        assert limits[3 * k] == pytest.approx((-math.radians(70), math.radians(70)))
        assert limits[3 * k + 1] == pytest.approx((-math.radians(90), math.radians(90)))
    masses = [p.getDynamicsInfo(robot, link, physicsClientId=c)[0] for link in range(-1, 18)]
    assert sum(masses) == pytest.approx(G.total_mass) and 2.0 <= G.total_mass <= 3.0


def test_robot_settles_standing_level_at_the_neutral_height(sim):
    x, y, heading, tilt = sim.pose()
    assert abs(x) < 0.01 and abs(y) < 0.01 and abs(heading) < 0.01
    assert tilt < math.radians(1.0)
    z = sim.base_state()[0][2]
    assert z == pytest.approx(G.standing_height, abs=0.01)
    q, _, _ = sim.joint_states()
    np.testing.assert_allclose(q, G.neutral_pose(), atol=0.02)


def test_primitive_follows_eq_10_with_shins_kept_vertical():
    rng = np.random.default_rng(3)
    genes = rng.uniform(-1, 1, (4, N_PARAMETERS))
    table = GaitTable(genes)
    t = 0.37
    q = table.joint_targets(t)
    rho = math.pi / 8 + (genes[:, 0] + 1) / 2 * 2 * math.pi
    for j, limit in enumerate([math.radians(70), math.radians(90)] * 6):
        eps, amp, phase = (
            genes[:, 1 + 3 * j],
            (genes[:, 2 + 3 * j] + 1) / 2,
            (genes[:, 3 + 3 * j] + 1) / 2,
        )
        p_j = eps + amp * np.tanh(rho * np.sin(2 * math.pi * (t * 1.0 + phase)))
        joint = 3 * (j // 2) + j % 2
        np.testing.assert_allclose(q[:, joint], np.clip(p_j, -1, 1) * limit)
    np.testing.assert_allclose(q[:, 2::3], math.pi / 2 - q[:, 1::3])  # C = -B + 90 deg
    specs = parameter_specs()
    assert len(specs) == 37 and specs[0].name == "rho"
    assert (specs[0].low, specs[0].high) == (math.pi / 8, math.pi / 8 + 2 * math.pi)
    assert {(s.low, s.high) for s in specs[1:]} == {(-1.0, 1.0), (0.0, 1.0)}


def test_servos_respect_the_velocity_and_torque_limits(sim):
    sim.reset()
    target = G.neutral_pose()
    target[0::3] = math.radians(70)  # every coxa swings 70 deg at once
    peak_velocity = peak_torque = 0.0
    for _ in range(30):
        sim.run(target[None, :])
        _, v, tau = sim.joint_states()
        peak_velocity = max(peak_velocity, np.abs(v).max())
        peak_torque = max(peak_torque, np.max(np.abs(tau) - G.joint_torques()))
    q, _, _ = sim.joint_states()
    assert peak_velocity <= G.max_joint_velocity * 1.01
    assert peak_torque <= 1e-9
    np.testing.assert_allclose(q[0::3], math.radians(70), atol=0.05)  # and it gets there


def test_a_tripod_gait_walks_and_its_mirror_image_mirrors_the_outcome(sim):
    genes = np.array([tripod(), tripod(amp_a=0.8)])
    genes[1, 1::6] = 0.3  # offset the A joints: a curved walk
    out = evaluate_genes(sim, np.vstack([genes, mirror_genes(genes)]), 2.0, 0.1, DISCARD_TILT)
    assert math.hypot(out[0, X], out[0, Y]) > 0.3 and out[0, TILT] < DISCARD_TILT
    # Left-right mirror: (x, y, heading) -> (x, -y, -heading), up to the simulator's
    # asymmetries (contact ordering), a few cm over 2 s.
    np.testing.assert_allclose(out[2:, X], out[:2, X], atol=0.05)
    np.testing.assert_allclose(out[2:, Y], -out[:2, Y], atol=0.05)
    np.testing.assert_allclose(out[2:, HEADING], -out[:2, HEADING], atol=0.15)


def test_same_primitive_gives_identical_outcomes_whatever_ran_before(sim):
    genes = np.random.default_rng(5).uniform(-1, 1, (6, N_PARAMETERS))
    forward = evaluate_genes(sim, genes, 2.0, 0.1, DISCARD_TILT)
    backward = evaluate_genes(sim, genes[::-1], 2.0, 0.1, DISCARD_TILT)[::-1]
    np.testing.assert_array_equal(forward, backward)
    fresh = HexapodSim()
    try:
        np.testing.assert_array_equal(
            evaluate_genes(fresh, genes[3:], 2.0, 0.1, DISCARD_TILT), forward[3:]
        )
    finally:
        fresh.close()


def test_results_do_not_depend_on_the_number_of_workers():
    genes = np.random.default_rng(6).uniform(-1, 1, (45, N_PARAMETERS))
    with EvaluationPool(functools.partial(HexapodSim, G, PhysicsSettings()), 1) as one:
        serial = one.evaluate(genes, 2.0, 0.1, DISCARD_TILT)
    with EvaluationPool(functools.partial(HexapodSim, G, PhysicsSettings()), 2) as two:
        parallel = two.evaluate(genes, 2.0, 0.1, DISCARD_TILT)
    np.testing.assert_array_equal(serial, parallel)


def test_a_primitive_that_topples_stops_early_and_is_discarded(sim):
    genes = np.random.default_rng(0).uniform(-1, 1, (30, N_PARAMETERS))
    out = evaluate_genes(sim, genes, 2.0, 0.1, DISCARD_TILT)
    toppled = out[:, TILT] > DISCARD_TILT
    assert 0 < toppled.sum() < len(genes)  # random gaits: some topple, some do not
    assert np.all(out[toppled, SECONDS] < 2.0) and np.all(
        out[~toppled, SECONDS] == pytest.approx(2.0)
    )
    robot = HexapodRobot(workers=1)
    try:
        outcome = robot.evaluate_primitives(genes, 2.0)
    finally:
        robot.close()
    np.testing.assert_array_equal(outcome.max_tilt, out[:, TILT])
    quality = circular_tilt_quality(outcome)
    assert np.all(np.isnan(quality[toppled]))
    assert np.all((quality[~toppled] > 0.0) & (quality[~toppled] <= 2.0))


def test_reset_places_the_robot_at_the_requested_pose():
    walls = wall_boxes(np.array([[1.0, -1.0, 1.0, 1.0]]), 0.01)
    sim = HexapodSim(walls=walls)
    try:
        sim.reset(-0.5, 0.2, math.radians(30))
        x, y, heading, tilt = sim.pose()
        assert (x, y) == pytest.approx((-0.5, 0.2), abs=1e-3)
        assert heading == pytest.approx(math.radians(30), abs=1e-3) and tilt < 0.02
        # The laser's forward beam meets the wall at x = 0.995 along the 30 deg heading.
        sim.reset(-0.5, 0.2, 0.0)
        scanner = Scanner(
            angle_min=float(np.float32(-0.1)), angle_increment=0.1, beams=3, range_max=2.0
        )
        ranges = scanner.scan(sim)
        assert ranges.dtype == np.float32
        assert ranges[1] == pytest.approx(1.495, abs=2e-3)
        sim.reset(-0.5, 0.2, math.pi)
        assert np.all(np.isinf(scanner.scan(sim)))  # facing away: nothing within 2 m
    finally:
        sim.close()
