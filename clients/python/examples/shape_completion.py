#!/usr/bin/env python3
"""Shape completion: an object seen from one side, completed by its symmetry (PerceptionService.CompleteShape).

A simulated depth camera (graspsim.testing.partial_view: 320 x 240 pixels, 0.45 m away, 35 degrees above the
table) sees a 5 cm cube and a can (r 3.3 cm, h 10 cm) standing on a table; the server filters the points, finds
the mirror plane perpendicular to the table by the visibility score, mirrors the points, fits normals and a
Poisson surface, and returns a closed mesh — and the paper's Delaunay baseline for comparison. Prints the plane,
the stages' times and how far the completed mesh is from the true shape; draws before/after pictures into
shape_completion.png when matplotlib is installed.

    python3 shape_completion.py --server 127.0.0.1:50051 [--out DIR]
"""
import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

import graspsim
from graspsim.testing import partial_view

WIDTH, HEIGHT, FOCAL = 320, 240, 300.0
INTRINSICS = (FOCAL, FOCAL, (WIDTH - 1) / 2, (HEIGHT - 1) / 2)


def seen_from_one_side(vertices, triangles, table_z: float, azimuth_deg: float = 200.0):
    """(camera pose, depth image, mask) of a mesh standing on the table, from 0.45 m and 35 degrees up."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    centre = (lo + hi) / 2
    a, e = np.radians(azimuth_deg), np.radians(35.0)
    eye = centre + 0.45 * np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    camera = partial_view.look_at(eye, centre)
    depth, mask = partial_view.render_depth(vertices, triangles, camera, WIDTH, HEIGHT, *INTRINSICS,
                                            noise_sigma=0.0005, seed=1)
    return camera, depth, mask


def complete(client, vertices, triangles, table_z: float, **kwargs):
    """Completes the mesh's one-sided view; returns (seen points, completed shape, baseline)."""
    camera, depth, mask = seen_from_one_side(vertices, triangles, table_z)
    table = [0, 0, table_z, 1, 0, 0, 0]
    shape = client.complete_shape(camera, depth=depth, intrinsics=INTRINSICS, mask=mask, table_pose=table,
                                  refinements=2, **kwargs)
    baseline = client.complete_shape(camera, depth=depth, intrinsics=INTRINSICS, mask=mask, method="delaunay")
    seen = partial_view.depth_to_points(depth, camera, *INTRINSICS, mask=mask)
    return seen, shape, baseline


def report(name: str, seen, shape, distance) -> None:
    t = shape.timings_ms
    print(f"{name}: {len(seen)} points seen; plane through {np.round(shape.plane_point, 4)} m, normal "
          f"{np.round(shape.plane_normal, 3)}, score {shape.score:.4f} ({shape.hypotheses} hypotheses); "
          f"{len(shape.triangles)} triangles; {t['total']:.1f} ms (filter {t['filter']:.1f}, symmetry "
          f"{t['symmetry']:.1f}, normals {t['normals']:.1f}, surface {t['surface']:.1f})")
    print(f"  completed mesh vertices are {1e3 * np.mean(np.abs(distance(shape.vertices))):.2f} mm from the true "
          f"surface on average")


def box_distance(size, centre):
    half = np.asarray(size) / 2

    def distance(points):
        q = np.abs(points - centre) - half
        outside = np.linalg.norm(np.maximum(q, 0), axis=1)
        return np.where(outside > 0, outside, -np.max(q, axis=1))
    return distance


def cylinder_distance(radius, height, base):
    def distance(points):
        p = points - base
        radial, axial = np.hypot(p[:, 0], p[:, 1]) - radius, np.abs(p[:, 2] - height / 2) - height / 2
        out = np.hypot(np.maximum(radial, 0), np.maximum(axial, 0))
        return np.where((radial > 0) | (axial > 0), out, -np.maximum(radial, axial))
    return distance


def draw(path: Path, panels) -> bool:
    """panels: (title, seen points, completed shape, baseline) per object → one PNG of before/after pictures."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    fig = plt.figure(figsize=(12, 4 * len(panels)))
    for row, (title, seen, shape, baseline) in enumerate(panels):
        for col, (label, mesh) in enumerate([("seen from one side", None), ("Delaunay baseline", baseline),
                                             ("mirrored + Poisson", shape)]):
            ax = fig.add_subplot(len(panels), 3, 3 * row + col + 1, projection="3d")
            if mesh is None:
                ax.scatter(seen[:, 0], seen[:, 1], seen[:, 2], s=1, c=seen[:, 2], cmap="viridis")
            else:
                ax.plot_trisurf(mesh.vertices[:, 0], mesh.vertices[:, 1], mesh.vertices[:, 2],
                                triangles=mesh.triangles, color="tab:orange" if mesh is shape else "tab:blue",
                                linewidth=0, alpha=0.9)
            ax.set_title(f"{title}: {label}")
            ax.view_init(elev=25, azim=20)  # from the side the camera did not see
            lo, hi = seen.min(axis=0) - 0.02, seen.max(axis=0) + 0.02
            ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
            ax.set_box_aspect(hi - lo)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return True


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051", help="host:port of graspsim-server")
    parser.add_argument("--out", default=None, help="directory for shape_completion.png (default: a temp dir)")
    args = parser.parse_args(argv)
    table_z = 0.75
    cube_v, cube_t = graspsim.meshes.box_mesh([0.05, 0.05, 0.05])
    cube_v = np.asarray(cube_v) + [0, 0, table_z + 0.025]
    can_v, can_t = partial_view.cylinder_mesh(0.033, 0.10, 64)
    can_v = can_v + [0.0, 0.0, table_z]
    try:
        with graspsim.connect(args.server) as client:
            panels = []
            for name, (v, t), distance in (
                    ("cube", (cube_v, cube_t), box_distance([0.05] * 3, [0, 0, table_z + 0.025])),
                    ("can", (can_v, can_t), cylinder_distance(0.033, 0.10, np.array([0, 0, table_z])))):
                seen, shape, baseline = complete(client, v, t, table_z, orientations=1 if name == "can" else 0)
                report(name, seen, shape, distance)
                panels.append((name, seen, shape, baseline))
    except graspsim.GraspsimError as err:
        print(f"shape completion failed: {err}", file=sys.stderr)
        return 1
    out = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="graspsim-shape-"))
    path = out / "shape_completion.png"
    if draw(path, panels):
        print(f"picture: {path}")
    else:
        print("(matplotlib not installed: no picture; pip install 'graspsim[plot]')")
    return 0


if __name__ == "__main__":
    sys.exit(main())
