"""complete_shapes: Client.complete_shape over many views on a pool of ServerActors, one Parquet dataset
(out_dir/shapes/<key>.parquet per view), with the same resume and retry as plan_grasp_database."""
from __future__ import annotations

import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Dict, Iterable, List, Optional, Sequence, Set, Tuple, Union

import numpy as np
from numpy.typing import NDArray
import pyarrow as pa

from graspsim._pose import as_pose
from graspsim.batch._dataset import canonical_json, sha256_hex, write_task, written_keys
from graspsim.batch._pool import PoolOptions, progress_bar, ray_session, run_pool
from graspsim.batch._summary import BatchSummary

if TYPE_CHECKING:
    from graspsim._client import Client

# a view of complete_shapes: {"name", "camera_pose", "points"} or with "depth", "intrinsics" (+ "mask"), optional
# "table_pose"; or a (name, camera_pose, points) tuple
ViewLike = Union[Dict[str, Any], Tuple[str, Any, Any]]

SHAPE_PARAMS = {"method", "orientations", "shifts", "octree_depth", "refinements", "fine_shifts", "voxel_size"}
_f64 = pa.float64()
SCHEMA = pa.schema([
    ("key", pa.string()), ("view", pa.string()), ("params", pa.string()), ("vertices", pa.int64()),
    ("triangles", pa.int64()), ("volume", _f64), ("centroid", pa.list_(_f64)), ("plane_point", pa.list_(_f64)),
    ("plane_normal", pa.list_(_f64)), ("score", _f64), ("input_points", pa.int64()), ("surface_points", pa.int64()),
    ("total_ms", _f64), ("mesh_vertices", pa.binary()), ("mesh_triangles", pa.binary()), ("error", pa.string()),
])


def volume_and_centroid(vertices: NDArray[np.floating[Any]], triangles: NDArray[np.integer[Any]]
                        ) -> Tuple[float, List[float]]:
    """Enclosed volume (m³) and its centroid of a closed, outward-oriented mesh (divergence theorem)."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    six_v = np.einsum("ij,ij->i", a, np.cross(b, c))
    volume = six_v.sum() / 6.0
    if abs(volume) < 1e-15:
        return 0.0, [float("nan")] * 3
    return float(volume), ((six_v[:, None] * (a + b + c)).sum(0) / (24.0 * volume)).tolist()


def _complete_task(client: Client, spec: Dict[str, Any], view: Dict[str, Any]) -> Dict[str, Any]:
    shape = client.complete_shape(view["camera_pose"], points=view.get("points"), depth=view.get("depth"),
                                  intrinsics=view.get("intrinsics"), mask=view.get("mask"),
                                  table_pose=view.get("table_pose"), timeout=spec["timeout"], progress=False,
                                  **spec["params"])  # the job's bar is the driver's; a worker has none
    volume, centroid = volume_and_centroid(shape.vertices, shape.triangles)
    return dict(spec["row"], vertices=len(shape.vertices), triangles=len(shape.triangles), volume=volume,
                centroid=centroid, score=shape.score, input_points=shape.input_points,
                surface_points=shape.surface_points, total_ms=shape.timings_ms["total"],
                plane_point=None if shape.plane_point is None else shape.plane_point.tolist(),
                plane_normal=None if shape.plane_normal is None else shape.plane_normal.tolist(),
                mesh_vertices=shape.vertices.astype("<f4").tobytes(),
                mesh_triangles=shape.triangles.astype("<u4").tobytes())


def _view(view: ViewLike) -> Dict[str, Any]:
    """A view: {"name", "camera_pose", "points"} or with "depth", "intrinsics" (+ "mask"), optional
    "table_pose"; or a (name, camera_pose, points) tuple."""
    if not isinstance(view, dict):
        name, camera_pose, points = view
        view = {"name": name, "camera_pose": camera_pose, "points": points}
    return dict(view)


def _view_key(view: Dict[str, Any], params_json: str) -> str:
    parts: List[Union[str, bytes]] = [params_json, canonical_json(as_pose(view["camera_pose"]).as_array().tolist())]
    for field in ("points", "depth", "mask"):
        if view.get(field) is not None:
            parts.append(field.encode() + np.ascontiguousarray(view[field], dtype="<f4").tobytes())
    for field in ("intrinsics", "table_pose"):
        if view.get(field) is not None:
            value = view[field] if field == "intrinsics" else as_pose(view[field]).as_array().tolist()
            parts.append(canonical_json([field, [float(v) for v in value]]))
    return sha256_hex(*parts)


def complete_shapes(views: Iterable[ViewLike], *, out_dir: Union[str, os.PathLike[str]],
                    params: Optional[Dict[str, Any]] = None,
                    workers: Optional[int] = None, progress: bool = True, server: Optional[str] = None,
                    address: Optional[str] = None, compute_threads: Optional[int] = None,
                    server_flags: Sequence[str] = (), retry_errors: bool = False,
                    timeout: float = 600.0) -> BatchSummary:
    """Completes every view (see _view) with Client.complete_shape(**params) on `workers` ServerActors; one row
    per view in out_dir/shapes/<key>.parquet (key: SHA-256 of the params, pose and cloud): counts, volume (m³)
    and centroid of the closed mesh, symmetry plane, score, the mesh itself (float32 / uint32 bytes), error."""
    started = time.perf_counter()
    params = dict(params or {})
    unknown = set(params) - SHAPE_PARAMS
    if unknown:
        raise ValueError(f"params: {sorted(unknown)} are not complete_shape parameters ({sorted(SHAPE_PARAMS)})")
    params_json = canonical_json(params)
    dataset = Path(out_dir) / "shapes"
    specs: List[Tuple[Dict[str, Any], Dict[str, Any]]] = []  # (task spec, the view without its name)
    seen: Set[str] = set()
    for view in map(_view, views):
        key = _view_key(view, params_json)
        if key not in seen:
            seen.add(key)
            specs.append((dict(row=dict(key=key, view=str(view["name"]), params=params_json), params=params,
                               timeout=timeout), {k: v for k, v in view.items() if k != "name"}))
    done_keys = written_keys(dataset, retry_errors)
    todo = [s for s in specs if s[0]["row"]["key"] not in done_keys]
    summary = BatchSummary(objects=len(specs), tasks=len(specs), skipped=len(specs) - len(todo), dataset=str(dataset))
    bar = None

    def on_result(i: int, status: str, value: Any) -> None:
        row = value if status == "ok" else dict(todo[i][0]["row"], error=value)
        write_task(dataset, row["key"], [row], SCHEMA)
        summary.done += 1
        summary.errors += status != "ok"
        if bar is not None:
            bar.update(1)

    try:
        with ray_session(address, bool(todo)):
            bar = progress_bar(progress, len(specs), summary.skipped, "shapes")
            stats = run_pool([(_complete_task, spec, view) for spec, view in todo], on_result,
                             PoolOptions(workers, server, compute_threads, server_flags, None, timeout + 60))
    finally:
        if bar is not None:
            bar.close()
    summary.add_pool(stats)
    summary.seconds = round(time.perf_counter() - started, 3)
    return summary
