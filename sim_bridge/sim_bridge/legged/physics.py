"""A legged robot in a PyBullet world: joint servos, resets, pose, tilt and a 2D laser.

Every actuated joint is a servo: a proportional controller on the joint angle whose
commanded velocity is clipped to the velocity limit and whose torque is clipped to the
torque limit (paper Appendix D). PyBullet's own position control ignores URDF velocity
limits, so each physics step reads the joint angles and commands
``clip(K (q* - q), -v_max, v_max)`` through a velocity motor of maximal force ``tau_max``;
Bullet solves that motor implicitly, so the loop is stable at any gain times step below 1.

Resets restore a saved state of the robot standing at rest (``restoreState``, about 6 us)
with ``deterministicOverlappingPairs=1``, so the same primitive from the same reset gives
bit-identical results whatever ran before it, in any process.

The robot's pose is PyBullet's base pose: the position of the root link's centre of mass
and the orientation of its inertial frame (for the hexapod, the body box's centre; for
the A1, 1.3 cm ahead of the trunk frame's origin).

Frames: world z up; the robot rests at the origin facing +x after :meth:`reset` unless a
pose is given. Angles in rad, lengths in m, times in s.
"""

from __future__ import annotations

import contextlib
import math
import os
import tempfile

import numpy as np

from evorbc_ros.robots.legged import LeggedGaitTable, gait_step_times
from sim_bridge.legged.settings import LeggedRobotSettings
from sim_bridge.quiet_pybullet import p

#: Collision groups: laser rays see only walls; the robot touches ground and walls.
WALL_GROUP, ROBOT_GROUP, GROUND_GROUP = 1, 2, 4


def _tilt(quaternion) -> float:
    """Angle (rad) between the body's z axis and the world's z axis."""
    qx, qy = quaternion[0], quaternion[1]
    cos_tilt = 1.0 - 2.0 * (qx * qx + qy * qy)  # R[2, 2] of the body rotation
    return math.acos(max(-1.0, min(1.0, cos_tilt)))


def _yaw(quaternion) -> float:
    """Heading (rad) of the body's x axis projected on the ground, in (-pi, pi]."""
    qx, qy, qz, qw = quaternion
    return math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


class RobotModelError(ValueError):
    """The URDF does not hold what the settings name (a joint or link)."""


class LeggedSim:
    """One legged robot (and optionally maze walls) in its own PyBullet client.

    Args:
        settings: the robot (URDF, gait, servos, physics).
        walls: ``(m, 6)`` wall boxes of :mod:`sim_bridge.geometry` (a maze), or None.
        gui: open PyBullet's GUI instead of running headless.
        rest_xy: where (m) the robot settles into its rest state: the origin without
            walls, otherwise a point 10 m beyond the walls so that it settles untouched.

    Raises:
        RobotModelError: a joint or link the settings name is not in the URDF.

    """

    def __init__(
        self,
        settings: LeggedRobotSettings,
        walls: np.ndarray | None = None,
        gui: bool = False,
        rest_xy: tuple[float, float] | None = None,
    ) -> None:
        self.settings = settings
        self.physics = settings.physics
        self.client = p.connect(p.GUI if gui else p.DIRECT)
        c = self.client
        p.setGravity(0.0, 0.0, -9.81, physicsClientId=c)
        p.setPhysicsEngineParameter(
            fixedTimeStep=self.physics.dt,
            numSubSteps=1,
            numSolverIterations=self.physics.solver_iterations,
            deterministicOverlappingPairs=1,
            physicsClientId=c,
        )
        self.ground = self._ground()
        boxes = np.empty((0, 6)) if walls is None else np.asarray(walls, dtype=np.float64)
        self.walls = self._walls(boxes) if len(boxes) else []
        if rest_xy is None and len(boxes):
            # Beyond every wall's far end in x (centre + half length).
            rest_xy = (float(np.max(boxes[:, 0] + boxes[:, 4])) + 10.0, 0.0)
        elif rest_xy is None:
            rest_xy = (0.0, 0.0)
        try:
            self.robot, self.joints, self.feet = self._load_robot(rest_xy)
        except RobotModelError:
            self.close()
            raise
        self.torques = list(settings.servo.torques)
        # Damage (docs/perturbations.md): joint column -> angle (rad) its servo holds
        # whatever the targets say (a locked knee); empty for the intact robot.
        self.locked: dict[int, float] = {}
        self.steps_done = 0  # physics steps since the last reset
        self._rest_state, self._rest_pose = self._settle()
        self.steps_done = 0  # the clock starts at rest

    # -- building the world --------------------------------------------------------

    def _ground(self) -> int:
        c = self.client
        shape = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=c)
        body = p.createMultiBody(0, shape, physicsClientId=c)
        p.changeDynamics(body, -1, lateralFriction=self.physics.friction, physicsClientId=c)
        p.setCollisionFilterGroupMask(body, -1, GROUND_GROUP, ROBOT_GROUP, physicsClientId=c)
        return body

    def _walls(self, boxes: np.ndarray) -> list[int]:
        """One static box per wall, ``wall_height`` tall, standing on the ground."""
        c, h = self.client, self.physics.wall_height
        bodies = []
        for cx, cy, ux, uy, half_length, half_thickness in np.asarray(boxes, dtype=np.float64):
            shape = p.createCollisionShape(
                p.GEOM_BOX, halfExtents=[half_length, half_thickness, 0.5 * h], physicsClientId=c
            )
            yaw = math.atan2(uy, ux)
            body = p.createMultiBody(
                0,
                shape,
                -1,
                [cx, cy, 0.5 * h],
                p.getQuaternionFromEuler([0.0, 0.0, yaw]),
                physicsClientId=c,
            )
            p.changeDynamics(body, -1, lateralFriction=self.physics.friction, physicsClientId=c)
            # Rays test with group 1 (WALL_GROUP) against the body's mask, so the mask
            # holds WALL_GROUP as well; static walls never collide with each other anyway.
            p.setCollisionFilterGroupMask(
                body, -1, WALL_GROUP, WALL_GROUP | ROBOT_GROUP, physicsClientId=c
            )
            bodies.append(body)
        return bodies

    @contextlib.contextmanager
    def _urdf_file(self):
        """The URDF's path; a generated URDF lives in a private temporary directory."""
        s = self.settings
        if s.urdf_text is None:
            yield s.urdf
            return
        # loadURDF reads files only.
        with tempfile.TemporaryDirectory(prefix=f"evorbc-{s.name}-") as tmp:
            path = os.path.join(tmp, f"{s.name}.urdf")
            with open(path, "w", encoding="utf-8") as f:
                f.write(s.urdf_text)
            yield path

    def _load_robot(self, xy: tuple[float, float]) -> tuple[int, list[int], list[int]]:
        """Load the URDF standing at ``xy``; its body id, actuated joints and foot links."""
        c, s = self.client, self.settings
        flags = p.URDF_USE_INERTIA_FROM_FILE
        if s.self_collision:
            flags |= p.URDF_USE_SELF_COLLISION
        # Without a spawn height, load 1 m up, pose the legs, and lower the robot until its
        # lowest collision shape is 1 mm above the ground.
        z = 1.0 if s.spawn_height is None else s.spawn_height
        with self._urdf_file() as path:
            robot = p.loadURDF(path, [xy[0], xy[1], z], flags=flags, physicsClientId=c)
        n = p.getNumJoints(robot, physicsClientId=c)
        infos = [p.getJointInfo(robot, j, physicsClientId=c) for j in range(n)]
        by_joint = {info[1].decode(): info for info in infos}
        by_link = {info[12].decode(): info[0] for info in infos}
        base = p.getBodyInfo(robot, physicsClientId=c)[0].decode()
        where = s.source or s.name
        if base != s.base_link:
            raise RobotModelError(f"{where}: links.base is {s.base_link!r}, the URDF's is {base!r}")
        joints = []
        for name in s.gait.joint_names:
            info = by_joint.get(name)
            if info is None or info[2] not in (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC):
                movable = [k for k, i in by_joint.items() if i[2] != p.JOINT_FIXED]
                raise RobotModelError(
                    f"{where}: joints: {name!r} is no movable joint of the URDF; "
                    f"its movable joints: {', '.join(movable)}"
                )
            joints.append(info[0])
        feet = []
        for name in s.foot_links:
            if name not in by_link:
                raise RobotModelError(f"{where}: links.feet: {name!r} is no link of the URDF")
            feet.append(by_link[name])
        mask = WALL_GROUP | ROBOT_GROUP | GROUND_GROUP
        for link in range(-1, n):
            p.changeDynamics(robot, link, lateralFriction=self.physics.friction, physicsClientId=c)
            p.setCollisionFilterGroupMask(robot, link, ROBOT_GROUP, mask, physicsClientId=c)
        for j, q in zip(joints, s.gait.standing_pose(), strict=True):
            p.resetJointState(robot, j, q, physicsClientId=c)
            # Free the joints from PyBullet's default velocity motors; our servos drive them.
            p.setJointMotorControl2(robot, j, p.VELOCITY_CONTROL, force=0.0, physicsClientId=c)
        if s.spawn_height is None:
            low = min(p.getAABB(robot, k, physicsClientId=c)[0][2] for k in range(-1, n))
            # The base pose is its centre of mass's; move it down as far as the shapes.
            (bx, by, bz), orn = p.getBasePositionAndOrientation(robot, physicsClientId=c)
            p.resetBasePositionAndOrientation(
                robot, [bx, by, bz - low + 0.001], orn, physicsClientId=c
            )
        return robot, joints, feet

    def _settle(self) -> tuple[int, tuple]:
        """Hold the standing pose for ``settle_time`` and save that rest state."""
        steps = self.physics.steps(self.physics.settle_time)
        self.run(np.tile(self.settings.gait.standing_pose(), (steps, 1)))
        pos, orn = p.getBasePositionAndOrientation(self.robot, physicsClientId=self.client)
        return p.saveState(physicsClientId=self.client), (pos, orn)

    # -- running -------------------------------------------------------------------

    def gait_table(self, genes: np.ndarray) -> LeggedGaitTable:
        """The robot's primitives ``genes`` ``(n, 1 + 3 k)``, ready to give joint targets."""
        return LeggedGaitTable(genes, self.settings.gait, self.settings.name)

    def reset(
        self, x: float | None = None, y: float | None = None, heading: float | None = None
    ) -> None:
        """Put the robot at rest at ``(x, y)`` facing ``heading`` (world frame); time 0.

        Without a pose the rest state is restored untouched, bit for bit (see
        :meth:`rest_pose`).
        """
        c = self.client
        p.restoreState(self._rest_state, physicsClientId=c)
        self.steps_done = 0
        if x is None or y is None or heading is None:
            return
        (_, _, pz), orn = self._rest_pose
        yaw0 = _yaw(orn)
        turn = heading - yaw0
        cos_t, sin_t = math.cos(turn), math.sin(turn)
        # Rotate the rest pose about its own centre, then move it: the legs follow.
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

    def rest_pose(self) -> tuple[float, float, float]:
        """``(x, y, heading)`` of the rest state (the start of every primitive evaluation)."""
        (x, y, _), orn = self._rest_pose
        return x, y, _yaw(orn)

    @property
    def time(self) -> float:
        """Seconds since the last reset (whole physics steps)."""
        return self.steps_done * self.physics.dt

    def step_times(self, steps: int) -> np.ndarray:
        """``(steps,)`` times (s since the last reset) at which the next steps start.

        Counted in whole steps times ``dt`` (never accumulated), so the onboard executor,
        which counts gait steps from the clock, computes bit-identical times.
        """
        return gait_step_times(self.steps_done, steps, self.physics.dt)

    def run(self, targets: np.ndarray, max_tilt: float = math.inf) -> tuple[float, float]:
        """Run one physics step per row of ``targets``, the servos tracking that row.

        Args:
            targets: ``(steps, joints)`` joint targets (rad), row ``k`` held during step
                ``k`` (sample the gait at :meth:`step_times`).
            max_tilt: stop early (rad) once the body tilts more than this.

        Returns:
            ``(largest tilt seen, rad; path length of the body centre in the ground
            plane, m)``, over the steps run.

        """
        c, robot, joints = self.client, self.robot, self.joints
        gain = self.settings.servo.gain
        v_max = self.settings.servo.max_velocity
        torques = self.torques
        velocity_control = p.VELOCITY_CONTROL
        get_states, set_motors = p.getJointStates, p.setJointMotorControlArray
        step, get_pose = p.stepSimulation, p.getBasePositionAndOrientation
        tilt_max = 0.0
        path = 0.0
        (x0, y0, _), _ = get_pose(robot, physicsClientId=c)
        # Plain floats, not numpy: a dozen joints are too few for numpy's per-call
        # overhead, and the same IEEE operations in the same order give the same bits. For
        # any x, ``v if x > v else (-v if x < -v else x)`` is ``np.clip(x, -v, v)`` (NaN
        # included).
        v_min = -v_max
        targets = np.asarray(targets, dtype=np.float64)
        if self.locked:
            targets = targets.copy()
            for column, angle in self.locked.items():
                targets[:, column] = angle
        for target in targets.tolist():
            velocity = []
            states = get_states(robot, joints, physicsClientId=c)
            for q_target, state in zip(target, states, strict=True):
                v = gain * (q_target - state[0])
                velocity.append(v_max if v > v_max else (v_min if v < v_min else v))
            set_motors(
                robot,
                joints,
                velocity_control,
                targetVelocities=velocity,
                forces=torques,
                physicsClientId=c,
            )
            step(physicsClientId=c)
            self.steps_done += 1
            (x, y, _), orn = get_pose(robot, physicsClientId=c)
            path += math.hypot(x - x0, y - y0)
            x0, y0 = x, y
            tilt = _tilt(orn)
            if tilt > tilt_max:
                tilt_max = tilt
                if tilt_max > max_tilt:
                    break
        return tilt_max, path

    # -- reading -------------------------------------------------------------------

    def base_pose(self) -> tuple[tuple, tuple]:
        """Body position (m) and orientation (xyzw quaternion), world frame.

        Each read asks PyBullet for the whole robot's state; a caller that needs the pose
        several times between two steps reads it once and passes it to :meth:`pose` and
        :meth:`laser` (the episode loop does, once per control cycle).
        """
        return p.getBasePositionAndOrientation(self.robot, physicsClientId=self.client)

    def pose(self, base: tuple | None = None) -> tuple[float, float, float, float]:
        """``(x, y, heading, tilt)`` of the body, world frame, m and rad.

        Args:
            base: :meth:`base_pose` read since the last step, or None to read it now.

        """
        (x, y, _), orn = self.base_pose() if base is None else base
        return x, y, _yaw(orn), _tilt(orn)

    def base_state(self) -> tuple[tuple, tuple, tuple, tuple]:
        """Body position (m), orientation (xyzw), linear (m/s) and angular (rad/s) velocity."""
        c = self.client
        pos, orn = p.getBasePositionAndOrientation(self.robot, physicsClientId=c)
        lin, ang = p.getBaseVelocity(self.robot, physicsClientId=c)
        return pos, orn, lin, ang

    def joint_states(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Joint angles (rad), velocities (rad/s) and applied motor torques (N m), per joint."""
        states = p.getJointStates(self.robot, self.joints, physicsClientId=self.client)
        return (
            np.array([s[0] for s in states]),
            np.array([s[1] for s in states]),
            np.array([s[3] for s in states]),
        )

    def reach_radius(self) -> float:
        """Radius (m) about the body centre holding every collision shape's bounding box.

        In the ground plane, now; at rest it is the footprint a start must keep clear of
        walls.
        """
        c = self.client
        (x, y, _), _ = self.base_pose()
        radius = 0.0
        for link in range(-1, p.getNumJoints(self.robot, physicsClientId=c)):
            (x0, y0, _), (x1, y1, _) = p.getAABB(self.robot, link, physicsClientId=c)
            for cx in (x0, x1):
                for cy in (y0, y1):
                    radius = max(radius, math.hypot(cx - x, cy - y))
        return radius

    def laser(
        self, angles: np.ndarray, max_range: float, height: float, base: tuple | None = None
    ) -> np.ndarray:
        """A 2D laser on the body: distances (m) to walls along ``angles`` (rad, body yaw).

        Rays stay horizontal at ``height`` m above the ground whatever the body's tilt
        (a 2D scanner levelled in the ground plane); no hit within ``max_range`` gives
        +inf (REP 117). ``base``: as in :meth:`pose`.
        """
        x, y, heading, _ = self.pose(base)
        if not self.walls:
            return np.full(len(angles), np.inf)
        world = heading + np.asarray(angles, dtype=np.float64)
        # rayTestBatch takes lists: build them directly rather than through a (beams, 3)
        # array (same arithmetic, less numpy overhead per scan).
        height = float(height)
        end_x = (x + max_range * np.cos(world)).tolist()
        end_y = (y + max_range * np.sin(world)).tolist()
        start = [[x, y, height]] * len(world)
        end = [[ex, ey, height] for ex, ey in zip(end_x, end_y, strict=True)]
        hits = p.rayTestBatch(
            start, end, collisionFilterMask=WALL_GROUP, physicsClientId=self.client
        )
        return np.array([h[2] * max_range if h[0] >= 0 else np.inf for h in hits])

    def close(self) -> None:
        """Disconnect the client."""
        if self.client is not None and p.isConnected(self.client):
            p.disconnect(self.client)
        self.client = None

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()
