"""The shape benchmark's full-resolution part (tests/bench/shape.py): the evaluation's objects and views rebuilt in
numpy — the camera, orientations and depth noise of tests/stress/shape_eval.cpp, with the focal length scaled so
each view holds ~39.4k points — and exact point-to-mesh distances, to score what the server's CompleteShape makes
of them. numpy + scipy only (the "ycb" extra), so the bench needs nothing beyond it.
"""
import itertools

import numpy as np
from scipy.spatial import cKDTree

from graspsim.testing.partial_view import cylinder_mesh, look_at

KINECT_W, KINECT_H, KINECT_F = 640, 480, 525.0  # the evaluation's camera (shape_eval.cpp kKinect)
NOISE_M = 0.001
POINTS = 39416  # the paper's large cloud (shape_eval.cpp's timing_39k)


def read_stl(path):
    """Binary STL → (vertices (3n, 3), triangles (n, 3)): a triangle soup, as shape_eval.cpp reads it."""
    data = open(path, "rb").read()
    count = int(np.frombuffer(data, "<u4", 1, 80)[0])
    record = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    v = np.frombuffer(data, record, count, 84)["v"].reshape(-1, 3).astype(np.float64)
    return v, np.arange(len(v)).reshape(-1, 3)


def box_mesh(sx, sy, sz):
    v = np.array([[(i & 1) - 0.5, (i >> 1 & 1) - 0.5, (i >> 2 & 1) - 0.5] for i in range(8)]) * (sx, sy, sz)
    f = [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
         [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]]
    return v, np.array(f)


def evaluation_objects(ycb_paths):
    """name → (vertices, triangles), standing on z = 0 and centred in x and y (shape_eval.cpp StandOnTable)."""
    objects = {"box_80x60x120mm": box_mesh(0.08, 0.06, 0.12), "cylinder_r35_h110mm": cylinder_mesh(0.035, 0.11, 64)}
    for path in ycb_paths:
        objects[path.rsplit("/", 1)[-1].rsplit(".", 1)[0]] = read_stl(path)
    out = {}
    for name, (v, f) in objects.items():
        lo, hi = v.min(0), v.max(0)
        out[name] = (v - [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]], np.asarray(f))
    return out


def turned(v, yaw):
    c, s = np.cos(yaw), np.sin(yaw)
    return v @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]).T


def render(v, f, pose, width, height, fx, cx, cy, noise, seed):
    """Depth along the optical axis (h, w; NaN off the object) and mask, by exact ray–triangle hits: each triangle
    is tested only against the pixel centres inside its projected bounding box (a z-buffer, no BVH needed)."""
    r, o = pose.rotation_matrix(), np.asarray(pose.position)
    cam = (v - o) @ r  # camera frame: x right, y down, z forward (every vertex in front of the camera here)
    uv = cam[:, :2] / cam[:, 2:] * fx + [cx, cy]
    t_uv = uv[f]
    c0 = np.clip(np.ceil(t_uv[..., 0].min(1)), 0, width).astype(np.int64)
    c1 = np.clip(np.floor(t_uv[..., 0].max(1)), -1, width - 1).astype(np.int64)
    r0 = np.clip(np.ceil(t_uv[..., 1].min(1)), 0, height).astype(np.int64)
    r1 = np.clip(np.floor(t_uv[..., 1].max(1)), -1, height - 1).astype(np.int64)
    ncol, nrow = np.maximum(c1 - c0 + 1, 0), np.maximum(r1 - r0 + 1, 0)
    count = ncol * nrow
    tri = np.repeat(np.arange(len(f)), count)
    local = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    col, row = c0[tri] + local % ncol[tri], r0[tri] + local // ncol[tri]
    d = np.stack([(col - cx) / fx, (row - cy) / fx, np.ones(len(col))], 1)  # z = 1: the hit's t is its depth
    a, e1, e2 = cam[f[tri, 0]], cam[f[tri, 1]] - cam[f[tri, 0]], cam[f[tri, 2]] - cam[f[tri, 0]]
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", p, e1)
    with np.errstate(divide="ignore", invalid="ignore"):  # Möller–Trumbore
        inv = 1 / det
        s = -a
        bu = np.einsum("ij,ij->i", p, s) * inv
        q = np.cross(s, e1)
        bv = np.einsum("ij,ij->i", d, q) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        hit = (np.abs(det) > 1e-18) & (bu >= 0) & (bv >= 0) & (bu + bv <= 1) & (t > 0)
    depth = np.full(width * height, np.inf)
    np.minimum.at(depth, row[hit] * width + col[hit], t[hit])
    mask = np.isfinite(depth)
    depth[mask] += np.random.default_rng(seed).normal(0, noise, int(mask.sum()))
    depth[~mask] = np.nan
    return depth.reshape(height, width), mask.reshape(height, width)


def view_39k(v, f, yaw, seed):
    """shape_eval.cpp's view of the object turned by yaw (0.6 m away, 35° up, aimed at half its height), its focal
    length and image scaled by √(39.4k / the 640 × 480 view's points) as its timing_39k does, then cropped to the
    mask's box plus the margin the symmetry score's window takes (max(16 px, half the box)) and one pixel: every
    pixel the server would look at, in a message under its 4 MB limit. → complete_shape's keyword arguments."""
    tv = turned(v, yaw)
    target = np.array([0, 0, 0.5 * tv[:, 2].max()])
    e = np.radians(35)
    pose = look_at(target + 0.6 * np.array([-np.cos(e), 0, np.sin(e)]), target)
    _, base = render(tv, f, pose, KINECT_W, KINECT_H, KINECT_F, 319.5, 239.5, 0, 0)
    scale = np.sqrt(POINTS / base.sum())
    w, h = int(np.ceil(KINECT_W * scale)) | 1, int(np.ceil(KINECT_H * scale)) | 1
    fx, cx, cy = KINECT_F * scale, (w - 1) / 2, (h - 1) / 2
    depth, mask = render(tv, f, pose, w, h, fx, cx, cy, NOISE_M, seed)
    rows, cols = np.nonzero(mask)
    margin = max(16, (np.ptp(cols) + 1) // 2, (np.ptp(rows) + 1) // 2) + 1
    y0, x0 = max(0, rows.min() - margin), max(0, cols.min() - margin)
    y1, x1 = min(h, rows.max() + margin + 1), min(w, cols.max() + margin + 1)
    return {"camera_pose": pose, "depth": depth[y0:y1, x0:x1].astype(np.float32), "mask": mask[y0:y1, x0:x1],
            "intrinsics": (fx, fx, cx - x0, cy - y0)}


def triangle_areas(tri):
    return 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)


def sample_surface(v, f, n, seed):
    """n points uniform over the surface (area-weighted triangles, uniform barycentrics)."""
    tri = v[f]
    area = triangle_areas(tri)
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(tri), n, p=area / area.sum())
    r1, r2 = np.sqrt(rng.random(n))[:, None], rng.random(n)[:, None]
    t = tri[pick]
    return (1 - r1) * t[:, 0] + r1 * (1 - r2) * t[:, 1] + r1 * r2 * t[:, 2]


def surface_centroid(v, f):
    """The surface's area-weighted centroid: what the mean of uniform samples tends to (shape_eval.cpp's
    centroid_pct), without their sampling noise."""
    tri = v[f]
    area = triangle_areas(tri)
    return (area[:, None] * tri.mean(1)).sum(0) / area.sum()


def point_triangle_distance(p, a, b, c):
    """Exact distances of points p to triangles (a, b, c), row by row (Ericson, Real-Time Collision Detection
    5.1.5: the closest point is a vertex, on an edge or inside; regions applied from least to most binding)."""
    dot = lambda x, y: np.einsum("ij,ij->i", x, y)  # noqa: E731
    ab, ac, ap, bp, cp = b - a, c - a, p - a, p - b, p - c
    d1, d2, d3, d4, d5, d6 = dot(ab, ap), dot(ac, ap), dot(ab, bp), dot(ac, bp), dot(ab, cp), dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        q = a + ab * (vb / denom)[:, None] + ac * (vc / denom)[:, None]
        on_bc = (va <= 0) & (d4 >= d3) & (d5 >= d6)
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        q = np.where(on_bc[:, None], b + (c - b) * w[:, None], q)
        on_ac = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
        q = np.where(on_ac[:, None], a + ac * (d2 / (d2 - d6))[:, None], q)
        q = np.where(((d6 >= 0) & (d5 <= d6))[:, None], c, q)
        on_ab = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
        q = np.where(on_ab[:, None], a + ab * (d1 / (d1 - d3))[:, None], q)
        q = np.where(((d3 >= 0) & (d4 <= d3))[:, None], b, q)
        q = np.where(((d1 <= 0) & (d2 <= 0))[:, None], a, q)
    return np.linalg.norm(p - q, axis=1)


class MeshDistance:
    """Exact distance from points to a triangle mesh's surface. Triangles are cut (longest edge halved) until every
    edge is at most twice the median and 1/40 of the bounding box's diagonal — the same surface in smaller pieces
    (a box's 12 triangles, a cylinder's long sides) — so each lies within a small radius R of its centroid. A
    point's distance to its 8 nearest centroids' triangles bounds the answer by u, and every triangle nearer than u
    has its centroid within u + R: those centroids are gathered (a k-d tree ball query) and every triangle that
    could still beat the bound (centroid distance − its own reach < u) is tested."""

    def __init__(self, v, f):
        tri = v[f]
        tri = tri[triangle_areas(tri) > 1e-14]  # slivers of zero area add no surface (and no closest point)
        limit = min(2 * np.median(np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2)),
                    np.linalg.norm(np.ptp(tri.reshape(-1, 3), axis=0)) / 40)
        while True:
            edge = np.linalg.norm(np.roll(tri, -1, axis=1) - tri, axis=2)  # edge k: vertex k → k + 1
            long = edge.max(1) > limit
            if not long.any():
                break
            t, k = tri[long], edge[long].argmax(1)
            i = np.arange(len(t))
            p0, p1, p2 = t[i, k], t[i, (k + 1) % 3], t[i, (k + 2) % 3]
            mid = (p0 + p1) / 2
            tri = np.concatenate([tri[~long], np.stack([p0, mid, p2], 1), np.stack([mid, p1, p2], 1)])
        self.tri = tri
        self.centroid = centroid = tri.mean(1)
        self.reach = np.linalg.norm(tri - centroid[:, None], axis=2).max(1)  # each triangle within this of its centroid
        self.radius = self.reach.max()
        self.tree = cKDTree(centroid)

    def __call__(self, points, chunk=5000):
        out = np.empty(len(points))
        for s in range(0, len(points), chunk):
            p = points[s:s + chunk]
            _, near = self.tree.query(p, k=8)
            bound = self._distance(np.repeat(p, 8, 0), near.ravel()).reshape(-1, 8).min(1)
            lists = self.tree.query_ball_point(p, bound + self.radius, return_sorted=False)
            counts = np.fromiter(map(len, lists), np.int64, len(lists))
            near = np.fromiter(itertools.chain.from_iterable(lists), np.int64, counts.sum())
            rows = np.repeat(np.arange(len(p)), counts)
            keep = np.linalg.norm(p[rows] - self.centroid[near], axis=1) - self.reach[near] < bound[rows]
            np.minimum.at(bound, rows[keep], self._distance(p[rows[keep]], near[keep]))
            out[s:s + chunk] = bound
        return out

    def _distance(self, p, index):
        t = self.tri[index]
        return point_triangle_distance(p, t[:, 0], t[:, 1], t[:, 2])
