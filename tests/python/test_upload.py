"""UploadFile: chunked uploads above the message limit, checksum and size checks, the upload limit."""
import hashlib

import grpc
import numpy as np
import pytest

import graspsim
from graspsim import inertia, meshes
from _support import IA, assert_rejected, cube_stl, header_for, raw_upload

MESSAGE_LIMIT = 1 << 20  # bytes, --max-message-bytes of the servers below


def fine_sphere():
    """A closed sphere of radius 0.05 m, 59 600 triangles: a ~3 MB binary STL."""
    return meshes.uv_sphere(0.05, 150, 200)


def test_chunked_upload_above_message_limit(start_server):
    server = start_server(f"--max-message-bytes={MESSAGE_LIMIT}")
    vertices, triangles = fine_sphere()
    stl = meshes.to_stl(vertices, triangles)
    assert len(stl) > 2.5 * MESSAGE_LIMIT
    with graspsim.connect(server.address) as client:
        scene_id = client.create_scene("upload").id
        info = client.upload_file(scene_id, "meshes/sphere.stl", stl, chunk_size=256 << 10)
        assert (info.path, info.size, info.sha256) == ("meshes/sphere.stl", len(stl), hashlib.sha256(stl).hexdigest())
        files = {f.path: f for f in client.get_scene(scene_id).files}
        assert files["meshes/sphere.stl"].size == len(stl)
        com, tensor = inertia.mesh_inertia(1.0, vertices, triangles)
        body = client.add_object(scene_id, "sphere", mesh_file="meshes/sphere.stl", mass=1.0, inertia=tensor,
                                 center_of_mass=com, pose=[0, 0, 1, 1, 0, 0, 0])
        assert body.triangle_count == len(triangles)
        assert body.collision[0].mesh_file == "meshes/sphere.stl"


def test_upload_from_local_path_and_replace(client, scene_id, tmp_path):
    path = tmp_path / "cube.stl"
    path.write_bytes(cube_stl(0.05))
    first = client.upload_file(scene_id, "cube.stl", path, chunk_size=100)
    second = client.upload_file(scene_id, "cube.stl", cube_stl(0.1))
    assert first.sha256 != second.sha256
    files = [f for f in client.get_scene(scene_id).files if f.path == "cube.stl"]
    assert len(files) == 1 and files[0].sha256 == second.sha256


def test_wrong_sha256_is_rejected(client, scene_id):
    data = cube_stl()
    header = header_for(scene_id, "bad.stl", data, sha256=hashlib.sha256(b"other").hexdigest())
    assert_rejected(client, scene_id, IA, ["header.sha256"], lambda: raw_upload(client, header, data, 300))
    assert "bad.stl" not in {f.path for f in client.get_scene(scene_id).files}


@pytest.mark.parametrize("size_delta", [-1, 1])
def test_total_size_mismatch_is_rejected(client, scene_id, size_delta):
    data = cube_stl()
    header = header_for(scene_id, "bad.stl", data, total_size=len(data) + size_delta)
    assert_rejected(client, scene_id, IA, ["total_size"], lambda: raw_upload(client, header, data, 300))


@pytest.mark.parametrize("path", ["../escape.stl", "/abs.stl", "", "a\\b.stl"])
def test_bad_path_is_rejected(client, scene_id, path):
    data = cube_stl()
    assert_rejected(client, scene_id, IA, ["header.path"], lambda: client.upload_file(scene_id, path, data))


def test_upload_above_max_upload_bytes(start_server):
    server = start_server("--max-upload-bytes=100000")
    with graspsim.connect(server.address) as client:
        scene_id = client.create_scene("limit").id
        client.upload_file(scene_id, "small.bin", bytes(100000))
        data = np.random.default_rng(1).bytes(150000)
        err = assert_rejected(client, scene_id, grpc.StatusCode.RESOURCE_EXHAUSTED, ["header.total_size", "100000"],
                              lambda: client.upload_file(scene_id, "big.bin", data, chunk_size=32 << 10))
        assert "big.bin" not in {f.path for f in client.get_scene(scene_id).files}, str(err)
