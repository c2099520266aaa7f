"""Shared helpers of the end-to-end tests: rejected-request and error checks, raw uploads, small URDFs and meshes."""
import contextlib
import hashlib
import time
from typing import Callable, Iterable

import grpc
import numpy as np
import pytest

import graspsim
from graspsim import meshes
from graspsim.testing import partial_view
from graspsim.v1 import scene_pb2

IA = grpc.StatusCode.INVALID_ARGUMENT
UNIT_INERTIA = np.eye(3) * 1e-3  # kg m^2, a valid tensor for tests that give it explicitly


def whole_scene(client, scene_id) -> graspsim.Scene:
    """The whole scene (with geometry) for before/after comparisons: a Scene compares by value, arrays included."""
    return client.get_scene(scene_id, include_geometry=True)


@contextlib.contextmanager
def expect_error(code, *parts):
    """A GraspsimError with `code` whose message holds every part."""
    with pytest.raises(graspsim.GraspsimError) as info:
        yield
    assert info.value.code == code, info.value
    for part in parts:
        assert part in info.value.message, info.value.message


def assert_rejected(client, scene_id: str, code: grpc.StatusCode, fragments: Iterable[str],
                    action: Callable[[], object]) -> graspsim.GraspsimError:
    """action() fails with code, its message names every fragment (case-insensitive), the scene is unchanged."""
    before = whole_scene(client, scene_id)
    with pytest.raises(graspsim.GraspsimError) as info:
        action()
    err = info.value
    assert err.code == code, f"expected {code.name}, got {err}"
    for fragment in fragments:
        assert str(fragment).lower() in err.message.lower(), f"message does not name {fragment!r}: {err}"
    assert whole_scene(client, scene_id) == before, f"scene changed by a rejected request ({err})"
    return err


def raw_upload(client, header: scene_pb2.UploadFileHeader, data: bytes, chunk_size: int = 1 << 20):
    """UploadFile with a hand-made header (e.g. a wrong sha256 or total_size); raises GraspsimError."""
    def chunks():
        yield scene_pb2.UploadFileChunk(header=header, data=data[:chunk_size])
        for start in range(chunk_size, len(data), chunk_size):
            yield scene_pb2.UploadFileChunk(data=data[start:start + chunk_size])

    try:
        return client.scene_stub.UploadFile(chunks(), timeout=60)
    except grpc.RpcError as err:
        raise graspsim._errors.from_rpc_error(err) from None


def header_for(scene_id: str, path: str, data: bytes, **overrides) -> scene_pb2.UploadFileHeader:
    values = dict(scene_id=scene_id, path=path, total_size=len(data), sha256=hashlib.sha256(data).hexdigest())
    values.update(overrides)
    return scene_pb2.UploadFileHeader(**values)


def cube_stl(edge: float = 0.05) -> bytes:
    """A binary STL of a closed cube of the given edge (m): 12 triangles."""
    return meshes.to_stl(*meshes.box_mesh([edge] * 3))


INERTIAL = '<inertial><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial>'


def link(name: str, geometry: str = '<box size="0.1 0.1 0.1"/>') -> str:
    return f'<link name="{name}">{INERTIAL}<collision><geometry>{geometry}</geometry></collision></link>'


def joint(name: str, parent: str, child: str, kind: str = "revolute") -> str:
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/>'
            f'</joint>')


def urdf(name: str, *elements: str) -> str:
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n' + "\n".join(elements) + "\n</robot>\n"


def two_link_urdf(mesh_path: str = "") -> str:
    """base (a box) + arm on a revolute joint; the arm is the mesh at mesh_path when given."""
    arm = f'<mesh filename="{mesh_path}"/>' if mesh_path else '<box size="0.05 0.05 0.2"/>'
    return urdf("arm", link("base"), link("arm", arm), joint("shoulder", "base", "arm"))


def wait_stopped(client, device_id, timeout=10.0):
    """Reads until the fingers stop; returns the last reading."""
    deadline = time.monotonic() + timeout
    while True:
        reading = client.send_command(device_id, read=True).reading
        if not reading.moving or time.monotonic() > deadline:
            return reading
        time.sleep(0.02)


# A rendered partial view: a cylinder (r 4 cm, h 10 cm) standing on the table z = 0, seen from 0.5 m and 30 degrees
# above by a 160 x 120 pinhole camera.
VIEW_W, VIEW_H, VIEW_F = 160, 120, 150.0
VIEW_INTRINSICS = (VIEW_F, VIEW_F, (VIEW_W - 1) / 2, (VIEW_H - 1) / 2)
VIEW_RADIUS, VIEW_HEIGHT = 0.04, 0.10


def cylinder_view():
    """(camera pose, depth image, object mask) of the cylinder."""
    vertices, triangles = partial_view.cylinder_mesh(VIEW_RADIUS, VIEW_HEIGHT, 48)
    centre = np.array([0.0, 0.0, VIEW_HEIGHT / 2])
    eye = centre + 0.5 * np.array([np.cos(np.radians(30)), 0.0, np.sin(np.radians(30))])
    camera = partial_view.look_at(eye, centre)
    depth, mask = partial_view.render_depth(vertices, triangles, camera, VIEW_W, VIEW_H, *VIEW_INTRINSICS)
    return camera, depth, mask
