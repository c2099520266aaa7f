"""PerceptionService end to end through the real server: CompleteShape from a rendered depth image and from points,
the Delaunay baseline, adding the mesh to a scene, SegmentScene, and every bad input with its code and field."""
import grpc
import numpy as np
import pytest

import graspsim
from graspsim.testing import partial_view
from graspsim.v1 import perception_pb2

from _support import (VIEW_F, VIEW_H, VIEW_HEIGHT, VIEW_INTRINSICS, VIEW_RADIUS, VIEW_W, cylinder_view,
                      expect_error)

IA = grpc.StatusCode.INVALID_ARGUMENT
RE = grpc.StatusCode.RESOURCE_EXHAUSTED
W, H, F = VIEW_W, VIEW_H, VIEW_F
INTRINSICS = VIEW_INTRINSICS
RADIUS, HEIGHT = VIEW_RADIUS, VIEW_HEIGHT


@pytest.fixture(scope="module")
def view():
    """A cylinder (r 4 cm, h 10 cm) standing on the table z = 0, seen from 0.5 m and 30 degrees above."""
    return cylinder_view()


def test_complete_shape_from_depth_image(client, view):
    camera, depth, mask = view
    stages = []
    shape = client.complete_shape(camera, depth=depth, intrinsics=INTRINSICS, mask=mask, table_pose=[0, 0, 0, 1, 0, 0, 0],
                                  orientations=1, refinements=3, on_progress=lambda s, f: stages.append(s))
    # Progress is newest-only (rpc/progress_run.h): a stage that ends before the previous message was written is
    # replaced, never queued, so the stages seen are in order, from the first, and end with done.
    order = ["filter", "symmetry", "normals", "surface", "done"]
    assert stages[0] == "filter" and stages[-1] == "done" and set(stages) <= set(order)
    assert [order.index(s) for s in stages] == sorted(order.index(s) for s in stages)
    assert shape.triangles.shape[0] > 100 and shape.vertices.shape[1] == 3
    # The plane contains the axis (within 2 mm) and is vertical; the mesh spans the whole cylinder, back included
    # (within 1 cm: at 160 x 120 pixels a pixel is 3 mm, and the strips beside the silhouette that perspective
    # hides from the camera and from the mirror are bridged by the surface fit).
    assert abs(np.dot(-shape.plane_point, shape.plane_normal)) < 0.002
    assert abs(shape.plane_normal[2]) < 1e-9
    lo, hi = shape.vertices.min(axis=0), shape.vertices.max(axis=0)
    np.testing.assert_allclose(lo, [-RADIUS, -RADIUS, 0.0], atol=0.01)
    np.testing.assert_allclose(hi, [RADIUS, RADIUS, HEIGHT], atol=0.01)
    assert shape.timings_ms["total"] > 0 and shape.input_points == int(mask.sum())


def test_complete_shape_from_points_is_deterministic(client, view):
    camera, depth, mask = view
    points = partial_view.depth_to_points(depth, camera, *INTRINSICS, mask=mask)
    a = client.complete_shape(camera, points=points, orientations=1)
    b = client.complete_shape(camera, points=points, orientations=1)
    assert a.vertices.tobytes() == b.vertices.tobytes() and a.triangles.tobytes() == b.triangles.tobytes()
    assert a.plane_normal is not None and a.input_points == len(points)


def test_fine_shifts_are_scored_after_the_grid_unless_turned_off(client, view):
    """absent = the server's 17 shifts after the 7 x 5 grid; 0 = the paper's grid alone; n = n more."""
    camera, depth, mask = view
    counts = {fine: client.complete_shape(camera, depth=depth, intrinsics=INTRINSICS, mask=mask, octree_depth=5,
                                          fine_shifts=fine, progress=False).hypotheses for fine in (None, 0, 5)}
    assert counts == {None: 35 + 17, 0: 35, 5: 35 + 5}


def test_delaunay_baseline_covers_only_the_seen_side(client, view):
    camera, depth, mask = view
    shape = client.complete_shape(camera, depth=depth, intrinsics=INTRINSICS, mask=mask, method="delaunay")
    assert shape.plane_normal is None
    assert len(np.unique(shape.vertices, axis=0)) <= 500
    # No completion: every vertex is one of the seen points (float32 on the wire).
    seen = partial_view.depth_to_points(depth, camera, *INTRINSICS, mask=mask)
    nearest = np.min(np.linalg.norm(shape.vertices[:, None, :] - seen[None, ::1, :], axis=2), axis=1)
    assert nearest.max() < 1e-6


def test_completed_mesh_becomes_a_scene_object(client, view):
    camera, depth, mask = view
    scene = client.create_scene("completion")
    shape = client.complete_shape(camera, depth=depth, intrinsics=INTRINSICS, mask=mask, orientations=1, refinements=3,
                                  table_pose=[0, 0, 0, 1, 0, 0, 0], add_to_scene_id=scene.id,
                                  object_name="can", object_mass=0.3)
    assert shape.body_id == "can"
    body = next(b for b in client.get_scene(scene.id).bodies if b.id == "can")
    assert body.inertial.mass == pytest.approx(0.3)
    # The body frame sits at the solid's centroid: about the cylinder's centre.
    np.testing.assert_allclose(body.pose.position, [0, 0, HEIGHT / 2], atol=0.005)


def test_segment_scene_finds_table_and_objects(client):
    rng = np.random.default_rng(1)
    xs, ys = np.meshgrid(np.arange(-0.3, 0.3, 0.005), np.arange(-0.3, 0.3, 0.005))
    table = np.column_stack([xs.ravel(), ys.ravel(), rng.normal(0, 0.001, xs.size)])
    objects = []
    for cx in (-0.15, 0.0, 0.15):
        cube = rng.uniform(-0.03, 0.03, (400, 3)) + [cx, 0.1, 0.045]
        objects.append(cube)
    seg = client.segment_scene(np.vstack([table] + objects))
    assert np.degrees(np.arccos(seg.table_normal[2])) < 1.0 and abs(seg.table_offset) < 0.002
    assert sorted(len(o) for o in seg.objects) == [400, 400, 400]


def raw_request(**fields):
    request = perception_pb2.CompleteShapeRequest(**fields)
    request.camera_pose.orientation.w = 1
    return request


def call(client, request):
    try:
        return list(client.perception_stub.CompleteShape(request, timeout=60))
    except grpc.RpcError as err:
        raise graspsim._errors.from_rpc_error(err) from None


def image(depth, mask=b"", width=W, height=H):
    return perception_pb2.DepthImage(intrinsics=perception_pb2.CameraIntrinsics(
        width=width, height=height, fx=F, fy=F, cx=W / 2, cy=H / 2), depth=depth, mask=mask)


BAD = {
    "empty cloud": (lambda: raw_request(cloud=perception_pb2.PointCloud()), IA, "cloud.points: the cloud is empty"),
    "all-NaN depth image": (lambda: raw_request(depth_image=image(np.full(W * H, np.nan, "<f4").tobytes())), IA,
                            "depth_image.depth: no pixel"),
    "points on a line": (lambda: raw_request(cloud=perception_pb2.PointCloud(points=np.column_stack(
        [np.linspace(0, 0.1, 100), np.zeros(100), np.full(100, 0.5)]).astype("<f4").tobytes())), IA,
        "lie on one line"),
    "mask of the wrong size": (lambda: raw_request(depth_image=image(np.full(W * H, 0.5, "<f4").tobytes(),
                                                                     mask=b"\x01" * 100)), IA,
                               "depth_image.mask: 100 bytes for a 160 x 120 image"),
    "cloud above the limit": (lambda: raw_request(cloud=perception_pb2.PointCloud(
        points=np.ones((20001, 3), "<f4").tobytes())), RE, "cloud.points: 20001 points exceed the limit of 20000"),
    "image above the limit": (lambda: raw_request(depth_image=image(b"", width=200, height=200)), RE,
                              "depth_image: 200 x 200 = 40000 pixels exceed the limit of 20000"),
    "ragged points": (lambda: raw_request(cloud=perception_pb2.PointCloud(points=b"\x00" * 13)), IA,
                      "cloud.points: 13 bytes"),
    "depth of the wrong size": (lambda: raw_request(depth_image=image(np.zeros(10, "<f4").tobytes())), IA,
                                "depth_image.depth: 10 values for a 160 x 120 image"),
    "bad depth": (lambda: raw_request(cloud=perception_pb2.PointCloud(points=np.ones((10, 3), "<f4").tobytes()),
                                      octree_depth=9), IA, "octree_depth: 9 is outside 5..8"),
    "one fine shift": (lambda: raw_request(cloud=perception_pb2.PointCloud(points=np.ones((10, 3), "<f4").tobytes()),
                                           fine_shifts=1), IA, "fine_shifts: 1 is outside 2..100"),
    "no input": (lambda: raw_request(), IA, "input: give depth_image or cloud"),
    "unknown scene": (lambda: raw_request(cloud=perception_pb2.PointCloud(points=np.ones((10, 3), "<f4").tobytes()),
                                          add_to_scene_id="nope"), grpc.StatusCode.NOT_FOUND, "nope"),
}


def test_bad_input_names_field_and_value(start_server):
    """Every case through one server whose cloud limit is 20000 points/pixels; each answers its code and field."""
    server = start_server("--max-cloud-points=20000")
    with graspsim.connect(server.address) as c:
        for case, (make, code, text) in BAD.items():
            with expect_error(code, text):
                call(c, make())
        # The server still answers after all of them.
        assert c.list_scenes() is not None


def test_segment_scene_rejects_empty_cloud(client):
    with expect_error(IA, "cloud.points: the cloud is empty"):
        client.segment_scene(np.zeros((0, 3)))


def test_shape_completion_example_saves_pictures(server, tmp_path):
    import subprocess
    import sys
    from pathlib import Path
    example = Path(__file__).resolve().parents[2] / "clients" / "python" / "examples" / "shape_completion.py"
    result = subprocess.run([sys.executable, str(example), "--server", server.address, "--out", str(tmp_path)],
                            capture_output=True, text=True, timeout=180)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "cube:" in result.stdout and "can:" in result.stdout
    pytest.importorskip("matplotlib")
    assert (tmp_path / "shape_completion.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
