"""plan_grasp_database: the grasp sets of many meshes for many hands, planned on a pool of ServerActors and
written as one Parquet dataset (one file per (mesh, hand) task, named by its key)."""
from __future__ import annotations

import hashlib
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Dict, Iterable, List, Optional, Sequence, Set, Tuple, Union, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray
import pyarrow as pa
import ray

from graspsim.batch._dataset import canonical_json, sha256_hex, write_task, written_keys
from graspsim.batch._pool import PoolOptions, progress_bar, ray_session, run_pool
from graspsim.batch._summary import BatchSummary

if TYPE_CHECKING:
    import trimesh

    from graspsim._client import Client

# a mesh of a job: a file path (STL/OBJ/PLY) or (name, vertices (n, 3) m, triangles (m, 3))
MeshSource = Union[str, "os.PathLike[str]", Tuple[str, ArrayLike, ArrayLike]]
# (name, vertices float32 (n, 3) m, triangles uint32 (m, 3))
LoadedMesh = Tuple[str, NDArray[np.float32], NDArray[np.uint32]]

# PlanGrasps parameters a job may set (Client.plan_grasps keywords); seed is the job's own argument.
PLAN_PARAMS = {"method", "friction", "preshapes", "standoffs", "rolls", "spacing", "circle_samples", "grasp_points",
               "max_candidates", "max_grasps", "object_material", "link_materials", "friction_pairs"}
# Slower hands first, so that short tasks fill the end of the job on every worker (unknown hands in between).
HAND_ORDER = {"schunk_sdh2": 0, "barrett_bh8_282": 1, "schunk_pg70": 3}
MESH_SUFFIXES = (".stl", ".obj", ".ply")

_f64 = pa.float64()
SCHEMA = pa.schema([
    ("key", pa.string()), ("mesh", pa.string()), ("mesh_sha256", pa.string()), ("hand", pa.string()),
    ("seed", pa.int64()), ("params", pa.string()), ("set_id", pa.string()), ("joint_ids", pa.list_(pa.string())),
    ("grasp_index", pa.int32()), ("candidate_index", pa.int64()), ("preshape", pa.string()),
    ("position", pa.list_(_f64)), ("quaternion", pa.list_(_f64)), ("joint_positions", pa.list_(_f64)),
    ("contact_points", pa.list_(pa.list_(_f64))), ("contact_normals", pa.list_(pa.list_(_f64))),
    ("contact_links", pa.list_(pa.string())), ("epsilon", _f64), ("volume", _f64), ("force_closure", pa.bool_()),
    ("task_candidates", pa.int64()), ("task_simulated", pa.int64()), ("task_force_closure", pa.int64()),
    ("task_seconds", _f64), ("error", pa.string()),
])


def mesh_sha256(vertices: NDArray[Any], triangles: NDArray[Any]) -> str:
    """The server's mesh hash (GraspSet.mesh_sha256): SHA-256 of float32 vertices then uint32 triangles."""
    return hashlib.sha256(vertices.astype("<f4").tobytes() + triangles.astype("<u4").tobytes()).hexdigest()


def load_mesh(source: MeshSource) -> LoadedMesh:
    """(name, vertices float32 (n, 3) m, triangles uint32 (m, 3)) of a path (STL/OBJ/PLY, read by trimesh, which
    welds duplicate vertices) or of a (name, vertices, triangles) tuple."""
    vertices: ArrayLike
    triangles: ArrayLike
    if isinstance(source, (str, os.PathLike)):
        import trimesh
        # force="mesh" makes it a Trimesh; trimesh types load() as returning any Geometry
        mesh = cast("trimesh.Trimesh", trimesh.load(os.fspath(source), force="mesh"))
        if len(mesh.faces) == 0:
            raise ValueError(f"{source}: no triangles loaded")
        name, vertices, triangles = Path(source).stem, mesh.vertices, mesh.faces
    else:
        name, vertices, triangles = source
    return (str(name), np.ascontiguousarray(vertices, dtype="<f4").reshape(-1, 3),
            np.ascontiguousarray(triangles, dtype="<u4").reshape(-1, 3))


def task_key(hand: str, mesh_hash: str, params_json: str) -> str:
    return sha256_hex(hand, mesh_hash, params_json)


def _plan_task(client: Client, spec: Dict[str, Any], mesh: Tuple[NDArray[np.float32], NDArray[np.uint32]]
               ) -> List[Dict[str, Any]]:
    """On an actor: plans one grasp set and returns its rows."""
    params: Dict[str, Any] = {k: (tuple(map(tuple, v)) if k == "grasp_points" else v)
                              for k, v in spec["plan"].items()}
    result = client.plan_grasps(spec["hand"], mesh=mesh, progress=False, timeout=spec["timeout"], **params)
    base = dict(spec["row"], set_id=result.set_id, joint_ids=list(result.joint_ids),
                task_candidates=result.candidates, task_simulated=result.simulated,
                task_force_closure=result.force_closure, task_seconds=result.seconds)
    rows: List[Dict[str, Any]] = []
    for i, g in enumerate(result.grasps):
        contacts = result.contacts[result.contacts["grasp"] == i]
        rows.append(dict(base, grasp_index=i, candidate_index=int(g["candidate_index"]), preshape=str(g["preshape"]),
                         position=g["hand_pose"][:3].tolist(), quaternion=g["hand_pose"][3:].tolist(),
                         joint_positions=g["joint_positions"].tolist(), contact_points=contacts["point"].tolist(),
                         contact_normals=contacts["normal"].tolist(), contact_links=contacts["link"].tolist(),
                         epsilon=float(g["epsilon"]), volume=float(g["volume"]),
                         force_closure=bool(g["force_closure"])))
    return rows or [base]  # a set without force-closure grasps: one row of counts


def _hand_params(params: Optional[Dict[str, Any]], hand: str) -> Dict[str, Any]:
    """params for every hand, or {hand: params} per hand (every key a non-parameter, every value a dict)."""
    params = params or {}
    per_hand = params and all(k not in PLAN_PARAMS | {"seed"} and isinstance(v, dict) for k, v in params.items())
    return dict(params.get(hand, {})) if per_hand else dict(params)


def plan_grasp_database(meshes: Iterable[MeshSource], hands: Sequence[str], *,
                        out_dir: Union[str, os.PathLike[str]], params: Optional[Dict[str, Any]] = None,
                        workers: Optional[int] = None,
                        seed: int = 1, progress: bool = True, server: Optional[str] = None,
                        address: Optional[str] = None, compute_threads: Optional[int] = None,
                        server_flags: Sequence[str] = (), store_dir: Optional[str] = None,
                        retry_errors: bool = False, timeout: float = 3600.0) -> BatchSummary:
    """Plans the grasp set of every mesh for every hand on `workers` ServerActors (default: the cluster's CPUs /
    compute_threads) and writes out_dir/grasps/<key>.parquet per task (docs/batch.md has the schema).

    meshes: paths (STL/OBJ/PLY) or (name, vertices (n, 3) m, triangles (m, 3)) tuples. params: Client.plan_grasps
    keywords (spacing, rolls, max_candidates, max_grasps, …) for every hand, or {hand: {...}} per hand; seed: the
    planner's seed. A task's key is SHA-256 of (hand, mesh SHA-256, canonical JSON of its params with the seed):
    tasks already written are skipped (resume; with retry_errors also those that recorded an error), a task whose
    worker died is resubmitted to another worker. A mesh that fails to load or that the server refuses gives one
    row with its `error` and the job goes on. address: a Ray cluster to join (None: Ray as initialised, else a
    local one). store_dir: keep each worker's server data dir (its SQLite grasp store) under it.
    """
    started = time.perf_counter()
    dataset = Path(out_dir) / "grasps"
    tasks, load_errors, names = _tasks(meshes, hands, params, seed, timeout)
    done_keys = written_keys(dataset, retry_errors)
    todo = [t for t in tasks if t["row"]["key"] not in done_keys]
    todo_errors = [(k, row) for k, row in load_errors if k not in done_keys]
    summary = BatchSummary(objects=len(names), hands=len(hands), tasks=len(tasks) + len(load_errors),
                           skipped=len(tasks) + len(load_errors) - len(todo) - len(todo_errors), dataset=str(dataset))
    for key, row in todo_errors:
        write_task(dataset, key, [row], SCHEMA)
        summary.done += 1
        summary.errors += 1
    bar = None

    def on_result(i: int, status: str, value: Any) -> None:
        spec = todo[i]
        rows = value if status == "ok" else [dict(spec["row"], error=value)]
        write_task(dataset, spec["row"]["key"], rows, SCHEMA)
        summary.done += 1
        summary.errors += status != "ok"
        if bar is not None:
            bar.update(1)

    try:
        with ray_session(address, bool(todo)):
            bar = progress_bar(progress, summary.tasks, summary.tasks - len(todo), "grasp sets")
            refs: Dict[int, Any] = {}  # mesh id -> its ray object ref
            calls: List[Tuple[Any, ...]] = []
            for spec in todo:  # each mesh once in the object store, whatever the number of hands
                mesh = spec.pop("mesh")
                if spec["mesh_id"] not in refs:
                    refs[spec["mesh_id"]] = ray.put(mesh)
                calls.append((_plan_task, spec, refs[spec["mesh_id"]]))
            stats = run_pool(calls, on_result, PoolOptions(workers, server, compute_threads, server_flags, store_dir,
                                                           timeout + 60))
    finally:
        if bar is not None:
            bar.close()
    summary.add_pool(stats)
    summary.seconds = round(time.perf_counter() - started, 3)
    return summary


def _tasks(meshes: Iterable[MeshSource], hands: Sequence[str], params: Optional[Dict[str, Any]], seed: int,
           timeout: float) -> Tuple[List[Dict[str, Any]], List[Tuple[str, Dict[str, Any]]], List[str]]:
    """(tasks, [(key, error row)] of meshes that did not load, mesh names): slower hands first, then mesh order."""
    loaded: List[LoadedMesh] = []
    load_errors: List[Tuple[str, Dict[str, Any]]] = []
    names: List[str] = []
    seen: Set[str] = set()
    for source in meshes:
        try:
            loaded.append(load_mesh(source))
            names.append(loaded[-1][0])
        except Exception as err:  # noqa: BLE001 - a bad file is one error row per hand, the job goes on
            name = Path(source).stem if isinstance(source, (str, os.PathLike)) else str(source[0])
            names.append(name)
            for hand in hands:
                plan = _plan_params(params, hand, seed)
                file_hash = _file_hash(source)
                key = task_key(hand, "file:" + file_hash, canonical_json(plan))
                load_errors.append((key, dict(key=key, mesh=name, hand=hand, seed=seed, params=canonical_json(plan),
                                              error=f"load: {type(err).__name__}: {err}")))
    tasks: List[Dict[str, Any]] = []
    digests = [mesh_sha256(vertices, triangles) for _, vertices, triangles in loaded]
    for hand in sorted(hands, key=lambda h: HAND_ORDER.get(h, 2)):
        plan = _plan_params(params, hand, seed)
        plan_json = canonical_json(plan)
        for mesh_id, ((name, vertices, triangles), digest) in enumerate(zip(loaded, digests)):
            key = task_key(hand, digest, plan_json)
            if key in seen:  # the same mesh twice (under any name): one task
                continue
            seen.add(key)
            row = dict(key=key, mesh=name, mesh_sha256=digest, hand=hand, seed=seed, params=plan_json)
            tasks.append(dict(hand=hand, plan=plan, row=row, mesh_id=mesh_id, mesh=(vertices, triangles),
                              timeout=timeout))
    return tasks, load_errors, names


def _plan_params(params: Optional[Dict[str, Any]], hand: str, seed: int) -> Dict[str, Any]:
    plan = _hand_params(params, hand)
    unknown = set(plan) - PLAN_PARAMS - {"seed"}
    if unknown:
        raise ValueError(f"params: {sorted(unknown)} are not plan_grasps parameters ({sorted(PLAN_PARAMS)})")
    if plan.get("seed", seed) != seed:
        raise ValueError(f"params: seed {plan['seed']} differs from seed={seed}")
    plan["seed"] = seed
    return plan


def _file_hash(source: Any) -> str:  # a MeshSource: Path() of a tuple raises the TypeError caught
    try:
        return sha256_hex(Path(source).read_bytes())
    except (OSError, TypeError):
        return sha256_hex(repr(source))
