"""PerceptionService methods of Client: shape completion of a partially seen object and table-top segmentation
(docs/perception.md). Arrays in, arrays out: points (n, 3) float m in the world, depth images (h, w) float m."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional

import grpc
import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspsim._errors import GraspsimError, translated_errors
from graspsim._ids import SceneLike, scene_id_of
from graspsim._pose import PoseLike, as_pose
from graspsim._progress import advance, progress_bar
from graspsim._stream import server_stream
from graspsim.v1 import common_pb2, perception_pb2, perception_pb2_grpc

METHODS = {"mirror": perception_pb2.COMPLETION_METHOD_MIRROR, "delaunay": perception_pb2.COMPLETION_METHOD_DELAUNAY}


def points_bytes(points: ArrayLike) -> bytes:
    """(n, 3) m → packed float32 x y z (the wire format of PointCloud.points)."""
    array = np.ascontiguousarray(np.asarray(points, dtype="<f4").reshape(-1, 3))
    return array.tobytes()


def points_from_bytes(data: bytes) -> NDArray[np.float64]:
    return np.frombuffer(data, dtype="<f4").reshape(-1, 3).astype(np.float64)


@dataclass
class CompletedShape:
    """CompleteShape's answer: the closed mesh (world frame, m; triangles counter-clockwise from outside), the
    symmetry plane (point, unit normal; None for the Delaunay baseline) and its visibility score, the per-stage
    wall times (ms) and point counts; body_id when the mesh was added to a scene."""
    vertices: NDArray[np.float64]
    triangles: NDArray[np.int64]
    plane_point: Optional[NDArray[np.float64]]
    plane_normal: Optional[NDArray[np.float64]]
    score: float
    hypotheses: int
    timings_ms: Dict[str, float]
    input_points: int
    filtered_points: int
    surface_points: int
    body_id: str = ""
    stages: List[str] = field(default_factory=list)  # the progress messages' stages, in order

    @classmethod
    def from_proto(cls, message: perception_pb2.CompleteShapeProgress, stages: List[str]) -> "CompletedShape":
        vertices = np.frombuffer(message.mesh.vertices, dtype="<f4").reshape(-1, 3).astype(np.float64)
        triangles = np.frombuffer(message.mesh.triangles, dtype="<u4").reshape(-1, 3).astype(np.int64)
        has_plane = message.HasField("plane")
        p, n = message.plane.point, message.plane.normal
        t = message.timings
        timings = {"observe": t.observe_ms, "filter": t.filter_ms, "symmetry": t.symmetry_ms,
                   "normals": t.normals_ms, "surface": t.surface_ms, "total": t.total_ms}
        return cls(vertices, triangles, np.array([p.x, p.y, p.z]) if has_plane else None,
                   np.array([n.x, n.y, n.z]) if has_plane else None, message.plane.score, message.plane.hypotheses,
                   timings, message.input_points, message.filtered_points, message.surface_points, message.body_id,
                   stages)


@dataclass
class SceneSegments:
    """SegmentScene's answer: the table plane {x : normal · x = offset} and each object's points (largest first)."""
    table_normal: NDArray[np.float64]
    table_offset: float
    objects: List[NDArray[np.float64]]


class PerceptionMethods:
    """Mixed into Client; needs self.channel and self.call_timeout."""

    channel: grpc.Channel
    call_timeout: float

    @property
    def perception_stub(self) -> perception_pb2_grpc.PerceptionServiceStub:
        stub = self.__dict__.get("_perception_stub")
        if stub is None:
            stub = self.__dict__["_perception_stub"] = perception_pb2_grpc.PerceptionServiceStub(self.channel)
        return stub

    def complete_shape(self, camera_pose: PoseLike, *, points: Optional[ArrayLike] = None,
                       depth: Optional[ArrayLike] = None, intrinsics: Optional[ArrayLike] = None,
                       mask: Optional[ArrayLike] = None,
                       table_pose: Optional[PoseLike] = None, method: str = "mirror", orientations: int = 0,
                       shifts: int = 0, octree_depth: int = 0, refinements: int = 0,
                       fine_shifts: Optional[int] = None, voxel_size: float = 0.0,
                       add_to_scene_id: SceneLike = "", object_name: str = "", object_mass: float = 0.0,
                       on_progress: Optional[Callable[[str, float], None]] = None,
                       timeout: Optional[float] = None, progress: bool = True) -> CompletedShape:
        """Completes one object seen from camera_pose (camera frame in the world: z forward, x right, y down).

        Input: points=(n, 3) m in the world, or depth=(h, w) m along the optical axis (0/NaN = no return) with
        intrinsics=(fx, fy, cx, cy) pixels and optionally mask=(h, w) bool (the object's pixels). table_pose: the
        table the object stands on (z up; its plane through the pose's origin) — the unseen underside is then
        closed flat; None = world z up, underside left to the surface fit. method "mirror" (symmetry search,
        Poisson surface) or "delaunay" (the paper's baseline). orientations × shifts hypotheses (0 = 7 × 5),
        octree_depth 5..8 (0 = 6), refinements 0..5 finer passes, fine_shifts 2..100 shifts refined at the best
        orientation (None = the server's 17, 0 = none: the paper's grid alone). add_to_scene_id: the mesh also
        becomes a free object of that scene (object_name, object_mass kg, 0 = 0.1). on_progress(stage, fraction)
        per stage; progress=True shows a tqdm bar on stderr. Leaving the call early (on_progress raising,
        KeyboardInterrupt) cancels the server's job.
        """
        request = perception_pb2.CompleteShapeRequest(
            camera_pose=as_pose(camera_pose).to_proto(), orientations=orientations, shifts=shifts,
            octree_depth=octree_depth, refinements=refinements, voxel_size=voxel_size,
            add_to_scene_id=scene_id_of(add_to_scene_id, "add_to_scene_id"), object_name=object_name,
            object_mass=object_mass)
        if fine_shifts is not None:
            request.fine_shifts = fine_shifts
        if method not in METHODS:
            raise ValueError(f"method: {method!r} is not one of {sorted(METHODS)}")
        request.method = METHODS[method]
        if table_pose is not None:
            request.table_pose.CopyFrom(as_pose(table_pose).to_proto())
        if (points is None) == (depth is None):
            raise ValueError("give exactly one of points=(n, 3) or depth=(h, w) with intrinsics")
        if points is not None:
            request.cloud.points = points_bytes(points)
        else:
            if intrinsics is None:
                raise ValueError("depth needs intrinsics=(fx, fy, cx, cy)")
            image = np.ascontiguousarray(np.asarray(depth, dtype="<f4"))
            if image.ndim != 2:
                raise ValueError(f"depth: shape {image.shape}; expected (height, width)")
            fx, fy, cx, cy = np.asarray(intrinsics, dtype=np.float64).reshape(4).tolist()
            request.depth_image.intrinsics.CopyFrom(perception_pb2.CameraIntrinsics(
                width=image.shape[1], height=image.shape[0], fx=fx, fy=fy, cx=cx, cy=cy))
            request.depth_image.depth = image.tobytes()
            if mask is not None:
                request.depth_image.mask = np.ascontiguousarray(np.asarray(mask).astype(np.uint8)).tobytes()
        stages: List[str] = []
        last = None
        with progress_bar(progress, 100, "shape", "%") as bar, \
                server_stream(self.perception_stub.CompleteShape(request, timeout=timeout)) as call:
            for message in call:
                stages.append(message.stage)
                advance(bar, round(100 * message.fraction), message.stage)
                if on_progress is not None:
                    on_progress(message.stage, message.fraction)
                last = message
        if last is None or last.stage != "done":
            raise GraspsimError.for_code(grpc.StatusCode.INTERNAL, "CompleteShape ended without a mesh")
        return CompletedShape.from_proto(last, stages)

    def segment_scene(self, points: ArrayLike, *, cluster_tolerance: float = 0.0, plane_threshold: float = 0.0,
                      min_cluster_points: int = 0) -> SceneSegments:
        """Splits a table-top cloud ((n, 3) m) into the table plane (RANSAC) and objects (Euclidean clusters).
        cluster_tolerance m (0 = 0.02), plane_threshold m (0 = 0.01), min_cluster_points (0 = 30)."""
        request = perception_pb2.SegmentSceneRequest(
            cloud=perception_pb2.PointCloud(points=points_bytes(points)), cluster_tolerance=cluster_tolerance,
            plane_threshold=plane_threshold, min_cluster_points=min_cluster_points)
        with translated_errors():
            response = self.perception_stub.SegmentScene(request, timeout=self.call_timeout)
        n = response.table_normal
        return SceneSegments(np.array([n.x, n.y, n.z]), response.table_offset,
                             [points_from_bytes(o.points) for o in response.objects])
