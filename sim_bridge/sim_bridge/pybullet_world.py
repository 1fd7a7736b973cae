"""A maze and a robot footprint in PyBullet: wall contact and laser rays.

Walls are one static triangle mesh built from the maze's wall boxes (vertical extrusions,
``wall_height`` tall). The robot's collision footprint is a sphere of the footprint radius
at the walls' mid-height: walls are vertical, so the sphere's 3D distance to them equals
the 2D distance of the footprint circle. Bullet intersects rays with triangles and spheres
with triangles exactly, so contact and ranges agree with the offline geometry to about
1e-15 m (its convex-box ray cast, by contrast, errs by up to 0.7 mm near box corners).

Each world has its own PyBullet client, so several can live in one process.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from sim_bridge.geometry import box_corners
from sim_bridge.maze import Maze
from sim_bridge.quiet_pybullet import p

#: Collision groups: rays and the footprint test only against walls.
WALL_GROUP, ROBOT_GROUP = 1, 2


#: Width (m) of the narrowest strip at each vertical edge of the wall mesh. Bullet accepts
#: a ray hit slightly outside a triangle, by a margin proportional to the triangle's size
#: (about 1e-5 of it here). Strips that double in width away from each edge keep every
#: triangle's margin inside the face, so a ray that passes a wall's end or corner misses it,
#: as it does for the offline boxes, unless it passes within about 1e-13 m.
EDGE_STRIP = 1e-9


def _cuts(width: float) -> list[float]:
    """Positions (fractions of ``width``) of strips doubling in width from both edges."""
    half, edges, w = 0.5 * width, [], EDGE_STRIP
    while sum(edges) + w < half:
        edges.append(w)
        w *= 2.0
    near = np.cumsum([0.0, *edges]) / width
    return sorted({*near.tolist(), 0.5, *(1.0 - near).tolist()})


def _face(a, b, height: float, vertices: list, indices: list) -> None:
    """A vertical wall face from corner ``a`` to ``b`` (xy), in strips (see EDGE_STRIP)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    cuts = _cuts(float(np.hypot(*(b - a))))
    for t0, t1 in itertools.pairwise(cuts):
        p0, p1 = a + t0 * (b - a), a + t1 * (b - a)
        base = len(vertices)
        vertices += [[*p0, 0.0], [*p1, 0.0], [*p1, height], [*p0, height]]
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]


def _wall_mesh(boxes: np.ndarray, height: float) -> tuple[list, list]:
    """Vertices and triangle indices of the boxes extruded from z = 0 to ``height``.

    Only the vertical faces: rays and the footprint stay at mid-height, far from the top
    and bottom.
    """
    vertices: list = []
    indices: list = []
    ring = (0, 1, 3, 2)  # corners of box_corners in order around the box
    for corners in box_corners(boxes):
        for k in range(4):
            _face(corners[ring[k]], corners[ring[(k + 1) % 4]], height, vertices, indices)
    return vertices, indices


class PyBulletMaze:
    """The walls of a maze and a robot footprint in a PyBullet client."""

    def __init__(
        self, maze: Maze, footprint_radius: float, wall_height: float = 0.2, gui: bool = False
    ) -> None:
        self.maze = maze
        self.radius = footprint_radius
        self.z = 0.5 * wall_height  # rays and the footprint sphere at mid-height
        self.client = p.connect(p.GUI if gui else p.DIRECT)
        c = self.client
        vertices, indices = _wall_mesh(maze.boxes, wall_height)
        shape = p.createCollisionShape(
            p.GEOM_MESH,
            vertices=vertices,
            indices=indices,
            flags=p.GEOM_FORCE_CONCAVE_TRIMESH,
            physicsClientId=c,
        )
        visual = -1
        if gui:
            visual = p.createVisualShape(
                p.GEOM_MESH,
                vertices=vertices,
                indices=indices,
                rgbaColor=[0.35, 0.35, 0.38, 1],
                physicsClientId=c,
            )
        self.walls = p.createMultiBody(0, shape, visual, [0, 0, 0], physicsClientId=c)
        p.setCollisionFilterGroupMask(
            self.walls, -1, WALL_GROUP, WALL_GROUP | ROBOT_GROUP, physicsClientId=c
        )
        footprint = p.createCollisionShape(
            p.GEOM_SPHERE, radius=footprint_radius, physicsClientId=c
        )
        body_visual = -1
        if gui:
            body_visual = p.createVisualShape(
                p.GEOM_CYLINDER,
                radius=footprint_radius,
                length=0.04,
                rgbaColor=[0.1, 0.45, 0.85, 1],
                physicsClientId=c,
            )
        self.robot = p.createMultiBody(0, footprint, body_visual, [0, 0, self.z], physicsClientId=c)
        p.setCollisionFilterGroupMask(self.robot, -1, ROBOT_GROUP, WALL_GROUP, physicsClientId=c)
        if gui:
            self._decorate()

    def _decorate(self) -> None:
        """Target marker and a camera over the maze (GUI only)."""
        c = self.client
        tx, ty = self.maze.target
        marker = p.createVisualShape(
            p.GEOM_CYLINDER,
            radius=self.maze.target_radius,
            length=0.005,
            rgbaColor=[0.9, 0.1, 0.1, 0.6],
            physicsClientId=c,
        )
        p.createMultiBody(0, -1, marker, [tx, ty, 0.003], physicsClientId=c)
        x0, y0, x1, y1 = self.maze.bounds()
        p.configureDebugVisualizer(p.COV_ENABLE_GUI, 0, physicsClientId=c)
        p.resetDebugVisualizerCamera(
            0.55 * (x1 - x0), 0.0, -70.0, [0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.0], physicsClientId=c
        )

    def footprint_clear(self, x: float, y: float) -> bool:
        """True if the footprint at ``(x, y)`` does not overlap a wall (touching is fine)."""
        p.resetBasePositionAndOrientation(
            self.robot, [x, y, self.z], [0, 0, 0, 1], physicsClientId=self.client
        )
        points = p.getClosestPoints(self.robot, self.walls, 0.001, physicsClientId=self.client)
        return all(pt[8] >= 0.0 for pt in points)

    def show_pose(self, x: float, y: float, heading: float) -> None:
        """Move the robot body (for the GUI and for queries)."""
        p.resetBasePositionAndOrientation(
            self.robot,
            [x, y, self.z],
            p.getQuaternionFromEuler([0, 0, heading]),
            physicsClientId=self.client,
        )

    def ranges(self, x: float, y: float, directions: np.ndarray, max_range: float) -> np.ndarray:
        """Distances (m) from ``(x, y)`` along world ``directions`` (rad) to the walls.

        No hit within ``max_range`` gives +inf (REP 117).
        """
        ends = [
            [x + max_range * math.cos(a), y + max_range * math.sin(a), self.z] for a in directions
        ]
        hits = p.rayTestBatch(
            [[x, y, self.z]] * len(ends),
            ends,
            collisionFilterMask=WALL_GROUP,
            physicsClientId=self.client,
        )
        return np.array([h[2] * max_range if h[0] >= 0 else np.inf for h in hits])

    def close(self) -> None:
        """Disconnect the client."""
        if self.client is not None and p.isConnected(self.client):
            p.disconnect(self.client)
        self.client = None
