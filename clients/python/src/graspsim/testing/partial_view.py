"""A simulated depth camera for shape completion (docs/perception.md): the partial view of a mesh that a real
camera would give — a depth image (m along the optical axis) and the object's mask — by exact ray casts
(Möller–Trumbore, numpy). Camera frame: z forward, x right, y down; pixel (u, v) = (column, row),
u = fx x / z + cx. For examples and tests; the server never needs it.
"""
from __future__ import annotations

from typing import Any, Optional, Sequence, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspsim._pose import Pose


def look_at(eye: ArrayLike, target: ArrayLike, up: ArrayLike = (0.0, 0.0, 1.0)) -> Pose:
    """The camera pose at `eye` looking at `target`, image rows running down along -up."""
    eye_at, target_at, up_axis = (np.asarray(v, dtype=float) for v in (eye, target, up))
    forward = target_at - eye_at
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, up_axis)
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    rotation = np.column_stack([right, down, forward])
    return Pose(position=eye_at, orientation=_quaternion_from_matrix(rotation))


def _quaternion_from_matrix(m: NDArray[np.float64]) -> NDArray[np.float64]:
    w = np.sqrt(max(0.0, 1.0 + m[0, 0] + m[1, 1] + m[2, 2])) / 2
    x = np.copysign(np.sqrt(max(0.0, 1.0 + m[0, 0] - m[1, 1] - m[2, 2])) / 2, m[2, 1] - m[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1.0 - m[0, 0] + m[1, 1] - m[2, 2])) / 2, m[0, 2] - m[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1.0 - m[0, 0] - m[1, 1] + m[2, 2])) / 2, m[1, 0] - m[0, 1])
    q = np.array([w, x, y, z])
    unit: NDArray[np.float64] = q / np.linalg.norm(q)
    return unit


def render_depth(vertices: ArrayLike, triangles: ArrayLike, camera_pose: Pose, width: int, height: int, fx: float,
                 fy: float, cx: float, cy: float, noise_sigma: float = 0.0, seed: int = 0
                 ) -> Tuple[NDArray[np.float32], NDArray[np.bool_]]:
    """(depth (h, w) float32 m, NaN where nothing was hit; mask (h, w) bool) of a mesh in the world frame.
    noise_sigma m: Gaussian noise on each depth (a stereo camera's)."""
    v = np.asarray(vertices, dtype=float).reshape(-1, 3)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    a, e1, e2 = v[t[:, 0]], v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]
    rotation = camera_pose.rotation_matrix()
    origin = np.asarray(camera_pose.position, dtype=float)
    us, vs = np.meshgrid(np.arange(width), np.arange(height))
    rays_camera = np.stack([(us.ravel() - cx) / fx, (vs.ravel() - cy) / fy, np.ones(us.size)], axis=1)
    rays = rays_camera @ rotation.T  # not normalised: t along it is the depth z
    depth = np.full(us.size, np.inf)
    s = origin - a  # (T, 3)
    for start in range(0, len(rays), 1024):
        d = rays[start:start + 1024][:, None, :]  # (R, 1, 3)
        p = np.cross(d, e2[None])  # (R, T, 3)
        det = np.einsum("rtk,tk->rt", p, e1)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            u = np.einsum("rtk,tk->rt", p, s) * inv
            q = np.cross(s, e1)  # (T, 3)
            w = np.einsum("rk,tk->rt", d[:, 0, :], q) * inv
            z = np.einsum("tk,tk->t", e2, q)[None, :] * inv
        hit = (np.abs(det) > 1e-15) & (u >= 0) & (w >= 0) & (u + w <= 1) & (z > 1e-6)
        z = np.where(hit, z, np.inf)
        depth[start:start + 1024] = z.min(axis=1)
    mask = np.isfinite(depth)
    if noise_sigma > 0:
        depth[mask] += np.random.default_rng(seed).normal(0.0, noise_sigma, int(mask.sum()))
    depth[~mask] = np.nan
    return depth.reshape(height, width).astype(np.float32), mask.reshape(height, width)


def depth_to_points(depth: ArrayLike, camera_pose: Pose, fx: float, fy: float, cx: float, cy: float,
                    mask: Optional[ArrayLike] = None) -> NDArray[np.float64]:
    """The world points (n, 3) of a depth image's valid (and masked) pixels."""
    image = np.asarray(depth, dtype=float)
    vs, us = np.nonzero(np.isfinite(image) & (image > 0) & (True if mask is None else np.asarray(mask, bool)))
    z = image[vs, us]
    local = np.stack([(us - cx) * z / fx, (vs - cy) * z / fy, z], axis=1)
    points: NDArray[np.float64] = (local @ camera_pose.rotation_matrix().T
                                   + np.asarray(camera_pose.position, dtype=float))
    return points


def cylinder_mesh(radius: float, height: float, segments: int = 48) -> Tuple[NDArray[np.float64], NDArray[np.int64]]:
    """A closed cylinder along z, base at z = 0: (vertices, triangles), counter-clockwise from outside."""
    angles = 2 * np.pi * np.arange(segments) / segments
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1)
    vertices: NDArray[np.float64]
    vertices = np.vstack([np.column_stack([ring, np.zeros(segments)]), np.column_stack([ring, np.full(segments, height)]),
                          [[0, 0, 0], [0, 0, height]]])
    tris = []
    bottom, top = 2 * segments, 2 * segments + 1
    for i in range(segments):
        j = (i + 1) % segments
        tris += [[i, j, segments + j], [i, segments + j, segments + i], [bottom, j, i], [top, segments + i, segments + j]]
    return vertices, np.array(tris, dtype=np.int64)
