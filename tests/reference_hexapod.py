"""The hexapod's simulation as it was before the generic legged robot (a test reference).

Commit fe6941e simulated the hexapod with code of its own: ``HexapodSim``,
``GaitTable`` and ``evaluate_genes``. They are kept here, trimmed of comments but
unchanged in every operation, so that tests can show that the hexapod, now an instance of
the generic legged robot (``sim_bridge/legged``, ``config/robots/hexapod.yaml``), gives
bit-identical results: the same primitive outcomes and the same maze episodes.
"""

from __future__ import annotations

import math
import os
import tempfile

import numpy as np

from evorbc_ros.robots.hexapod import RHO_HIGH, RHO_LOW, HexapodGeometry
from sim_bridge.hexapod.urdf import hexapod_urdf
from sim_bridge.legged.settings import PhysicsSettings
from sim_bridge.quiet_pybullet import p

WALL_GROUP, ROBOT_GROUP, GROUND_GROUP = 1, 2, 4


class GaitTable:
    """Eq. 10-11 for the hexapod's 12 evolved joints, C = 90 deg - B."""

    def __init__(self, genes, geometry: HexapodGeometry | None = None):
        g = np.clip(np.atleast_2d(np.asarray(genes, dtype=np.float64)), -1.0, 1.0)
        self.geometry = geometry or HexapodGeometry()
        unit = 0.5 * (g + 1.0)
        self.rho = RHO_LOW + unit[:, 0] * (RHO_HIGH - RHO_LOW)
        self.offset = g[:, 1::3]
        self.amplitude = unit[:, 2::3]
        self.phase = unit[:, 3::3]
        self.limits = self.geometry.evolved_limits()

    def __len__(self) -> int:
        return len(self.rho)

    def evolved_targets(self, t, rows=None) -> np.ndarray:
        sel = slice(None) if rows is None else rows
        t = np.asarray(t, dtype=np.float64)
        t_col = t[:, None] if t.ndim else t
        wave = np.sin(2.0 * math.pi * (t_col * self.geometry.frequency + self.phase[sel]))
        p_ = self.offset[sel] + self.amplitude[sel] * np.tanh(self.rho[sel][:, None] * wave)
        return np.clip(p_, -1.0, 1.0) * self.limits

    def joint_targets(self, t, rows=None) -> np.ndarray:
        evolved = np.atleast_2d(self.evolved_targets(t, rows))
        q = np.empty((evolved.shape[0], 18))
        q[:, 0::3] = evolved[:, 0::2]
        q[:, 1::3] = evolved[:, 1::2]
        q[:, 2::3] = 0.5 * math.pi - evolved[:, 1::2]
        return q


def _tilt(quaternion) -> float:
    qx, qy = quaternion[0], quaternion[1]
    return math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (qx * qx + qy * qy))))


def _yaw(quaternion) -> float:
    qx, qy, qz, qw = quaternion
    return math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


class HexapodSim:
    """One hexapod (and optionally maze walls) in its own PyBullet client."""

    def __init__(self, geometry=None, physics=None, walls=None, gui=False, rest_xy=None):
        self.geometry = geometry or HexapodGeometry()
        self.physics = physics or PhysicsSettings()
        self.client = c = p.connect(p.DIRECT)
        p.setGravity(0.0, 0.0, -9.81, physicsClientId=c)
        p.setPhysicsEngineParameter(
            fixedTimeStep=self.physics.dt,
            numSubSteps=1,
            numSolverIterations=self.physics.solver_iterations,
            deterministicOverlappingPairs=1,
            physicsClientId=c,
        )
        shape = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=c)
        self.ground = p.createMultiBody(0, shape, physicsClientId=c)
        p.changeDynamics(self.ground, -1, lateralFriction=self.physics.friction, physicsClientId=c)
        p.setCollisionFilterGroupMask(self.ground, -1, GROUND_GROUP, ROBOT_GROUP, physicsClientId=c)
        boxes = np.empty((0, 6)) if walls is None else np.asarray(walls, dtype=np.float64)
        self.walls = []
        h = self.physics.wall_height
        for cx, cy, ux, uy, half_length, half_thickness in boxes:
            shape = p.createCollisionShape(
                p.GEOM_BOX, halfExtents=[half_length, half_thickness, 0.5 * h], physicsClientId=c
            )
            orn = p.getQuaternionFromEuler([0.0, 0.0, math.atan2(uy, ux)])
            body = p.createMultiBody(0, shape, -1, [cx, cy, 0.5 * h], orn, physicsClientId=c)
            p.changeDynamics(body, -1, lateralFriction=self.physics.friction, physicsClientId=c)
            p.setCollisionFilterGroupMask(
                body, -1, WALL_GROUP, WALL_GROUP | ROBOT_GROUP, physicsClientId=c
            )
            self.walls.append(body)
        if rest_xy is None and len(boxes):
            rest_xy = (float(np.max(boxes[:, 0] + boxes[:, 4])) + 10.0, 0.0)
        elif rest_xy is None:
            rest_xy = (0.0, 0.0)
        g = self.geometry
        with tempfile.TemporaryDirectory(prefix="evorbc-hexapod-") as tmp:
            path = os.path.join(tmp, "hexapod.urdf")
            with open(path, "w", encoding="utf-8") as f:
                f.write(hexapod_urdf(g))
            flags = p.URDF_USE_INERTIA_FROM_FILE | p.URDF_USE_SELF_COLLISION
            self.robot = p.loadURDF(
                path, [rest_xy[0], rest_xy[1], g.standing_height + 0.001], flags=flags,
                physicsClientId=c,
            )  # fmt: skip
        mask = WALL_GROUP | ROBOT_GROUP | GROUND_GROUP
        for link in range(-1, p.getNumJoints(self.robot, physicsClientId=c)):
            p.changeDynamics(
                self.robot, link, lateralFriction=self.physics.friction, physicsClientId=c
            )
            p.setCollisionFilterGroupMask(self.robot, link, ROBOT_GROUP, mask, physicsClientId=c)
        for j, q in enumerate(g.neutral_pose()):
            p.resetJointState(self.robot, j, q, physicsClientId=c)
            p.setJointMotorControl2(self.robot, j, p.VELOCITY_CONTROL, force=0.0, physicsClientId=c)
        self.joints = list(range(p.getNumJoints(self.robot, physicsClientId=c)))
        self.torques = g.joint_torques().tolist()
        self.steps_done = 0
        self.run(np.tile(g.neutral_pose(), (self.physics.steps(self.physics.settle_time), 1)))
        self._rest_pose = p.getBasePositionAndOrientation(self.robot, physicsClientId=c)
        self._rest_state = p.saveState(physicsClientId=c)
        self.steps_done = 0

    def reset(self, x=None, y=None, heading=None) -> None:
        c = self.client
        p.restoreState(self._rest_state, physicsClientId=c)
        self.steps_done = 0
        if x is None or y is None or heading is None:
            return
        (_, _, pz), orn = self._rest_pose
        turn = heading - _yaw(orn)
        cos_t, sin_t = math.cos(turn), math.sin(turn)
        rotation = p.getQuaternionFromEuler([0.0, 0.0, turn])
        _, new_orn = p.multiplyTransforms([0, 0, 0], rotation, [0, 0, 0], orn)
        p.resetBasePositionAndOrientation(self.robot, [x, y, pz], new_orn, physicsClientId=c)
        lin, ang = p.getBaseVelocity(self.robot, physicsClientId=c)
        p.resetBaseVelocity(
            self.robot,
            [cos_t * lin[0] - sin_t * lin[1], sin_t * lin[0] + cos_t * lin[1], lin[2]],
            [cos_t * ang[0] - sin_t * ang[1], sin_t * ang[0] + cos_t * ang[1], ang[2]],
            physicsClientId=c,
        )

    def rest_pose(self):
        (x, y, _), orn = self._rest_pose
        return x, y, _yaw(orn)

    @property
    def time(self) -> float:
        return self.steps_done * self.physics.dt

    def step_times(self, steps: int) -> np.ndarray:
        return (self.steps_done + np.arange(steps)) * self.physics.dt

    def run(self, targets, max_tilt=math.inf):
        c, robot, joints = self.client, self.robot, self.joints
        gain, v_max = self.geometry.position_gain, self.geometry.max_joint_velocity
        tilt_max = path = 0.0
        (x0, y0, _), _ = p.getBasePositionAndOrientation(robot, physicsClientId=c)
        for target in np.asarray(targets, dtype=np.float64).tolist():
            velocity = []
            states = p.getJointStates(robot, joints, physicsClientId=c)
            for q_target, state in zip(target, states, strict=True):
                v = gain * (q_target - state[0])
                velocity.append(v_max if v > v_max else (-v_max if v < -v_max else v))
            p.setJointMotorControlArray(
                robot, joints, p.VELOCITY_CONTROL, targetVelocities=velocity,
                forces=self.torques, physicsClientId=c,
            )  # fmt: skip
            p.stepSimulation(physicsClientId=c)
            self.steps_done += 1
            (x, y, _), orn = p.getBasePositionAndOrientation(robot, physicsClientId=c)
            path += math.hypot(x - x0, y - y0)
            x0, y0 = x, y
            tilt = _tilt(orn)
            if tilt > tilt_max:
                tilt_max = tilt
                if tilt_max > max_tilt:
                    break
        return tilt_max, path

    def base_pose(self):
        return p.getBasePositionAndOrientation(self.robot, physicsClientId=self.client)

    def pose(self, base=None):
        (x, y, _), orn = self.base_pose() if base is None else base
        return x, y, _yaw(orn), _tilt(orn)

    def joint_states(self):
        states = p.getJointStates(self.robot, self.joints, physicsClientId=self.client)
        return tuple(np.array([s[k] for s in states]) for k in (0, 1, 3))

    def laser(self, angles, max_range, height, base=None):
        x, y, heading, _ = self.pose(base)
        if not self.walls:
            return np.full(len(angles), np.inf)
        world = heading + np.asarray(angles, dtype=np.float64)
        end_x = (x + max_range * np.cos(world)).tolist()
        end_y = (y + max_range * np.sin(world)).tolist()
        start = [[x, y, float(height)]] * len(world)
        end = [[ex, ey, float(height)] for ex, ey in zip(end_x, end_y, strict=True)]
        hits = p.rayTestBatch(
            start, end, collisionFilterMask=WALL_GROUP, physicsClientId=self.client
        )
        return np.array([h[2] * max_range if h[0] >= 0 else np.inf for h in hits])

    def close(self) -> None:
        if self.client is not None and p.isConnected(self.client):
            p.disconnect(self.client)
        self.client = None


def evaluate_genes(sim, genes, eval_time, control_period, max_tilt) -> np.ndarray:
    """Outcome rows ``x, y, heading, path, tilt, seconds`` of primitives run from rest."""
    table = GaitTable(genes, sim.geometry)
    x0, y0, h0 = sim.rest_pose()
    c0, s0 = math.cos(h0), math.sin(h0)
    per_period = sim.physics.steps(control_period)
    periods = round(eval_time / control_period)
    out = np.empty((len(table), 6))
    for i in range(len(table)):
        sim.reset()
        times = sim.step_times(per_period * periods)
        targets = table.joint_targets(times, np.full(len(times), i))
        heading = tilt = path = seconds = 0.0
        for k in range(periods):
            t_max, d = sim.run(targets[k * per_period : (k + 1) * per_period], max_tilt)
            tilt, path = max(tilt, t_max), path + d
            x, y, yaw, _ = sim.pose()
            heading += math.remainder(yaw - h0 - heading, 2.0 * math.pi)
            seconds = sim.time
            if tilt > max_tilt:
                break
        dx, dy = x - x0, y - y0
        out[i] = (c0 * dx + s0 * dy, -s0 * dx + c0 * dy, heading, path, tilt, seconds)
    return out
