"""Independent re-check of planned Panda paths among MotionBenchMaker obstacles, in PyBullet (no graspsim code).

The robot is panda_spherized.urdf (the model the server plans with) loaded into a DIRECT PyBullet client with a
fixed base at the origin (its visual meshes stripped: collision is spheres only); obstacles are GEOM_BOX /
GEOM_CYLINDER / GEOM_SPHERE bodies with collision margin 0 (Bullet's default 1 mm margin rounds box edges and
corners and makes distances up to 0.7 mm too large; with 0, box distances are exact and cylinder distances carry
GJK's error of a few µm: _check_distances compares them with closed forms at start-up). Self collision: every
pair of links with collision geometry that panda.srdf does not list in <disable_collisions>.

Sampling bound. A path is linear in joint space between waypoints: q(t) = q0 + t (q1 - q0), t in [0, 1]. A point p
of link k moves at |v| = |sum_i qdot_i a_i x (p - o_i)| <= sum_i |qdot_i| |p - o_i| over the joints i that move
k. R_ik >= |p - o_i| for every point of k's geometry in every configuration: the lengths of the joint offsets along
the chain from joint i to k, plus the sphere's offset in k and its radius (triangle inequality, read from the URDF).
So over a step h of t, no point of link k moves more than h * sum_i |q1_i - q0_i| R_ik (its "speed"); relative to a
link a upstream of k, only the joints between a and k count (the joints above a move both rigidly). At each
sample we take, per link, its distance to the nearest obstacle, and per self pair their distance (both capped at
CLEARANCE_CAP), and advance t by the largest h with h * speed <= max(distance, RESOLUTION) for every link and
pair: where something is farther than 1 mm it cannot be reached within the step (conservative advancement: no
contact between the samples), and nearer than that nothing moves more than 1 mm between two checks. Each
waypoint is checked. A sample is in collision when a closest-point distance is below PENETRATION (-1e-6 m).
"""
from __future__ import annotations

import math
import os
import tempfile
import xml.etree.ElementTree as ET
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Sequence, Tuple

import numpy as np

PENETRATION = -1e-6        # m: a distance below this is a collision
RESOLUTION = 1e-3          # m: largest motion between two checks of anything nearer than this to a contact
CLEARANCE_CAP = 0.05       # m: closest points are asked for within this distance
ENDPOINT_TOLERANCE = 1e-9  # rad: the path's first and last waypoints against start and goal
LIMIT_TOLERANCE = 1e-9     # rad: waypoints against the URDF's joint limits


@dataclass
class PathCheck:
    ok: bool
    samples: int = 0
    problems: List[str] = field(default_factory=list)   # what went wrong, first few


def _floats(text) -> List[float]:
    return [float(v) for v in (text or "0 0 0").split()]


@contextmanager
def _quiet_stdout():
    """PyBullet prints "argv[0]=" on stdout when it connects; the benchmark's stdout is its JSON."""
    saved = os.dup(1)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


class _Chain:
    """Kinematic facts from the URDF: per link, the arm joints that move it and the lever bounds R_ik."""

    def __init__(self, root, arm_joints: Sequence[str]):
        joints = {j.get("name"): j for j in root.iter("joint")}
        self.parent: Dict[str, Tuple[str, str, float]] = {}   # link -> (parent link, joint, |offset|)
        for name, j in joints.items():
            origin = j.find("origin")
            offset = float(np.linalg.norm(_floats(origin.get("xyz") if origin is not None else None)))
            self.parent[j.find("child").get("link")] = (j.find("parent").get("link"), name, offset)
        self.reach: Dict[str, float] = {}   # link -> farthest collision point from the link's frame origin
        for link in root.iter("link"):
            far = 0.0
            for col in link.findall("collision"):
                sphere = col.find("geometry/sphere")
                if sphere is None:
                    raise ValueError(f"link {link.get('name')}: a collision that is not a sphere")
                origin = col.find("origin")
                far = max(far, float(np.linalg.norm(_floats(origin.get("xyz") if origin is not None else None)))
                          + float(sphere.get("radius")))
            self.reach[link.get("name")] = far
        self.arm = list(arm_joints)
        self.limits = np.array([[float(joints[n].find("limit").get(k)) for k in ("lower", "upper")]
                                for n in arm_joints])

    def levers(self, link: str) -> np.ndarray:
        """R_ik for each arm joint i (0 for joints that do not move the link)."""
        out = np.zeros(len(self.arm))
        length = self.reach[link]   # chain length from the current joint's origin to the link's farthest point
        while link in self.parent:
            parent, joint, offset = self.parent[link]
            if joint in self.arm:
                out[self.arm.index(joint)] = length   # o_i is the child link's frame origin
            length += offset
            link = parent
        return out

    def relative_levers(self, a: str, b: str) -> np.ndarray:
        """Bounds of the motion of one link's points in the other's frame, per arm joint."""
        la, lb = self.levers(a), self.levers(b)
        moves_a, moves_b = la > 0, lb > 0
        if not (moves_a & ~moves_b).any():       # a upstream of b (or both moved by the same joints)
            return np.where(moves_a, 0.0, lb)
        if not (moves_b & ~moves_a).any():
            return np.where(moves_b, 0.0, la)
        return la + lb                            # neither above the other: each link's own motion


class PandaChecker:
    """Loads the robot once; set_obstacles(...) per problem, check_path(waypoints, start, goal) per path."""

    def __init__(self, urdf: Path, srdf: Path, arm_joints: Sequence[str]):
        import pybullet
        from pybullet_utils import bullet_client
        with _quiet_stdout():
            self.p = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
        root = ET.parse(urdf).getroot()
        self.chain = _Chain(root, arm_joints)
        for link in root.iter("link"):
            for visual in link.findall("visual"):
                link.remove(visual)
        with tempfile.NamedTemporaryFile("wb", suffix=".urdf", delete=False) as tmp:
            tmp.write(ET.tostring(root))
        try:
            self.robot = self.p.loadURDF(tmp.name, useFixedBase=True, basePosition=[0, 0, 0])
        finally:
            Path(tmp.name).unlink()
        self.link_index: Dict[str, int] = {self.p.getBodyInfo(self.robot)[0].decode(): -1}
        joint_index = {}
        for j in range(self.p.getNumJoints(self.robot)):
            info = self.p.getJointInfo(self.robot, j)
            joint_index[info[1].decode()] = j
            self.link_index[info[12].decode()] = j
        self.link_name = {i: n for n, i in self.link_index.items()}
        self.arm = [joint_index[name] for name in arm_joints]
        self.links = [i for i in self.link_index.values() if self.p.getCollisionShapeData(self.robot, i)]
        self.link_levers = np.array([self.chain.levers(self.link_name[i]) for i in self.links])
        self.row = {i: k for k, i in enumerate(self.links)}
        disabled = set()
        for entry in ET.parse(srdf).getroot().iter("disable_collisions"):
            disabled.add(frozenset((entry.get("link1"), entry.get("link2"))))
        self.self_pairs = [(a, b) for k, a in enumerate(self.links) for b in self.links[k + 1:]
                           if frozenset((self.link_name[a], self.link_name[b])) not in disabled]
        self.pair_levers = np.array([self.chain.relative_levers(self.link_name[a], self.link_name[b])
                                     for a, b in self.self_pairs]).reshape(-1, len(self.arm))
        self.obstacles: List[Tuple[int, str]] = []
        self._check_distances()

    def _check_distances(self) -> None:
        """PyBullet's distances against closed forms for the shapes used here (margin 0): sphere to a box's face,
        edge and corner, and to a cylinder's side, cap and rim; within 1e-5 m."""
        p = self.p
        box = self._add("box", (0.6, 0.4, 0.04), (0, 0, 0), (0, 0, 0, 1))
        cyl = self._add("cylinder", (0.03, 0.14), (2, 0, 0), (0, 0, 0, 1))
        probe = self._add("sphere", (0.012,), (0, 0, 5), (0, 0, 0, 1))
        s3, s2 = math.sqrt(3), math.sqrt(2)
        cases = [(box, (0, 0, 0.042), 0.01), (box, (0, 0, 0.031), -0.001), (box, (0.315, 0.0, 0.0), 0.003),
                 (box, (0.31, 0.21, 0.0), s2 * 0.01 - 0.012), (box, (0.31, 0.21, 0.03), s3 * 0.01 - 0.012),
                 (cyl, (2.052, 0, 0), 0.01), (cyl, (2.041, 0, 0), -0.001), (cyl, (2, 0, 0.084), 0.002),
                 (cyl, (2.04, 0, 0.08), s2 * 0.01 - 0.012)]
        for body, where, expected in cases:
            p.resetBasePositionAndOrientation(probe, where, (0, 0, 0, 1))
            got = min(c[8] for c in p.getClosestPoints(probe, body, 0.1))
            if abs(got - expected) > 1e-5:
                raise RuntimeError(f"PyBullet distance {got} at {where}, closed form {expected}")
        for body in (box, cyl, probe):
            p.removeBody(body)

    def _add(self, kind: str, size, position, orientation_xyzw) -> int:
        p = self.p
        if kind == "box":
            shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=[s / 2 for s in size])
        elif kind == "cylinder":
            shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=size[0], height=size[1])
        elif kind == "sphere":
            shape = p.createCollisionShape(p.GEOM_SPHERE, radius=size[0])
        else:
            raise ValueError(kind)
        body = p.createMultiBody(baseMass=0, baseCollisionShapeIndex=shape, basePosition=list(position),
                                 baseOrientation=list(orientation_xyzw))
        p.changeDynamics(body, -1, collisionMargin=0.0)
        return body

    def set_obstacles(self, obstacles) -> None:
        """obstacles: tests/data/mbm.py Obstacles (kind, id, size, position, orientation xyzw)."""
        for body, _ in self.obstacles:
            self.p.removeBody(body)
        self.obstacles = [(self._add(o.kind, o.size, o.position, o.orientation), o.id) for o in obstacles]

    def _sample(self, q, found: List[str], where: str) -> Tuple[np.ndarray, np.ndarray]:
        """Distances at q (capped): per robot link to the obstacles, per self pair; collisions go to found."""
        p, robot = self.p, self.robot
        for joint, value in zip(self.arm, q):
            p.resetJointState(robot, joint, float(value))
        to_obstacles = np.full(len(self.links), CLEARANCE_CAP)
        for body, name in self.obstacles:
            for c in p.getClosestPoints(robot, body, CLEARANCE_CAP):
                row = self.row[c[3]]
                to_obstacles[row] = min(to_obstacles[row], c[8])
                if c[8] < PENETRATION and len(found) < 5:
                    found.append(f"{where}: {self.link_name[c[3]]} in {name} by {-c[8] * 1e3:.3f} mm")
        to_self = np.full(len(self.self_pairs), CLEARANCE_CAP)
        for k, (a, b) in enumerate(self.self_pairs):
            for c in p.getClosestPoints(robot, robot, CLEARANCE_CAP, a, b):
                to_self[k] = min(to_self[k], c[8])
                if c[8] < PENETRATION and len(found) < 5:
                    found.append(f"{where}: {self.link_name[a]} in {self.link_name[b]} by {-c[8] * 1e3:.3f} mm")
        return to_obstacles, to_self

    def check_path(self, waypoints: np.ndarray, start, goal) -> PathCheck:
        """waypoints (n, 7) in arm_joints order; start, goal (7,)."""
        result = PathCheck(ok=True)
        waypoints = np.asarray(waypoints, dtype=np.float64)
        if waypoints.ndim != 2 or waypoints.shape[0] < 1 or waypoints.shape[1] != len(self.arm):
            return PathCheck(False, 0, [f"waypoints of shape {waypoints.shape}"])
        if np.max(np.abs(waypoints[0] - start)) > ENDPOINT_TOLERANCE:
            result.problems.append(f"first waypoint {waypoints[0].tolist()} is not the start {list(start)}")
        if np.max(np.abs(waypoints[-1] - goal)) > ENDPOINT_TOLERANCE:
            result.problems.append(f"last waypoint {waypoints[-1].tolist()} is not the goal {list(goal)}")
        limits = self.chain.limits
        outside = (waypoints < limits[:, 0] - LIMIT_TOLERANCE) | (waypoints > limits[:, 1] + LIMIT_TOLERANCE)
        if outside.any():
            row, col = np.argwhere(outside)[0]
            result.problems.append(f"waypoint {row}: joint {col + 1} at {waypoints[row, col]} outside its limits")
        found: List[str] = []
        distances = self._sample(waypoints[0], found, "waypoint 0")
        result.samples = 1
        for k in range(1, len(waypoints)):
            q0, q1 = waypoints[k - 1], waypoints[k]
            dq = np.abs(q1 - q0)
            speeds = (self.link_levers @ dq, self.pair_levers @ dq)   # m per unit t
            t = 0.0
            while True:
                step = min((np.maximum(d[s > 0], RESOLUTION) / s[s > 0]).min(initial=np.inf)
                           for d, s in zip(distances, speeds))
                t += step
                if t >= 1.0:
                    break
                distances = self._sample(q0 + t * (q1 - q0), found, f"segment {k} t={t:.4f}")
                result.samples += 1
            distances = self._sample(q1, found, f"waypoint {k}")
            result.samples += 1
        result.problems.extend(found)
        result.ok = not result.problems
        return result
