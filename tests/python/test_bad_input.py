"""Every rejected input: the status code, a message naming the field or value, and an unchanged scene."""
import grpc
import numpy as np
import pytest

import graspsim
from graspsim import meshes
from graspsim.v1 import common_pb2, scene_pb2
from _support import IA, UNIT_INERTIA, assert_rejected, joint, link, urdf

NOT_FOUND, EXISTS = grpc.StatusCode.NOT_FOUND, grpc.StatusCode.ALREADY_EXISTS
FAILED, EXHAUSTED = grpc.StatusCode.FAILED_PRECONDITION, grpc.StatusCode.RESOURCE_EXHAUSTED
NAN, INF = float("nan"), float("inf")
CUBE = meshes.box_mesh([0.05, 0.05, 0.05])


def box(sid, c, size=(0.1, 0.1, 0.1), mass=1.0, inertia=UNIT_INERTIA, pose=None, name="new"):
    return lambda: c.add_object(sid, name, box=size, mass=mass, inertia=inertia, pose=pose)


def mesh(sid, c, vertices, triangles):
    return lambda: c.add_object(sid, "new", mesh=(vertices, triangles), mass=1.0, inertia=UNIT_INERTIA)


def raw_add_object(sid, c, geometry: common_pb2.Geometry):
    """AddObject through the raw stub, for byte-level payloads the client API cannot produce."""
    inertial = common_pb2.Inertial(mass=1.0, ixx=1e-3, iyy=1e-3, izz=1e-3)
    request = scene_pb2.AddObjectRequest(scene_id=sid, name="new", geometry=geometry, inertial=inertial)

    def call():
        try:
            c.scene_stub.AddObject(request, timeout=30)
        except grpc.RpcError as err:
            raise graspsim._errors.from_rpc_error(err) from None
    return call


def robot(sid, c, text):
    return lambda: c.add_robot(sid, "bot", urdf=text)


ODD_VERTICES = common_pb2.Geometry(mesh=common_pb2.MeshData(vertices=b"\0" * 100,
                                                            triangles=np.zeros(3, "<u4").tobytes()))
CASES = {
    "nan position": (IA, ["pose.position", "nan"], lambda s, c: box(s, c, pose=[NAN, 0, 0, 1, 0, 0, 0])),
    "inf position": (IA, ["pose.position", "inf"], lambda s, c: box(s, c, pose=[0, INF, 0, 1, 0, 0, 0])),
    "nan box size": (IA, ["geometry.box.size", "nan"], lambda s, c: box(s, c, size=(0.1, NAN, 0.1))),
    "inf box size": (IA, ["geometry.box.size", "inf"], lambda s, c: box(s, c, size=(INF, 0.1, 0.1))),
    "negative box size": (IA, ["geometry.box.size", "-0.1"], lambda s, c: box(s, c, size=(0.1, 0.1, -0.1))),
    "nan mass": (IA, ["inertial.mass", "nan"], lambda s, c: box(s, c, mass=NAN)),
    "inf mass": (IA, ["inertial.mass", "inf"], lambda s, c: box(s, c, mass=INF)),
    "zero mass": (IA, ["inertial.mass", "0"], lambda s, c: box(s, c, mass=0.0)),
    "negative mass": (IA, ["inertial.mass", "-2"], lambda s, c: box(s, c, mass=-2.0)),
    "zero quaternion": (IA, ["pose.orientation", "norm 0"], lambda s, c: box(s, c, pose=[0, 0, 1, 0, 0, 0, 0])),
    "quaternion of norm 2": (IA, ["pose.orientation", "norm 2"], lambda s, c: box(s, c, pose=[0, 0, 1, 2, 0, 0, 0])),
    "negative inertia": (IA, ["inertial", "positive definite"], lambda s, c: box(
        s, c, inertia=np.diag([-1.0, 1.0, 1.0]))),
    "inertia triangle inequality": (IA, ["inertial", "triangle inequality"], lambda s, c: box(
        s, c, inertia=np.diag([3.0, 1.0, 1.0]))),
    "geometry without inertial, strict": (IA, ["inertial", "strict"], lambda s, c: lambda: c.add_object(
        s, "new", sphere=0.1, strict=True)),
    "geometry without inertial, from_file": (IA, ["inertial", "FROM_FILE"], lambda s, c: lambda: c.add_object(
        s, "new", sphere=0.1, inertia_source="from_file")),
    "import options density": (IA, ["import_options.density", "-1"], lambda s, c: lambda: c.add_object(
        s, "new", sphere=0.1, density=-1.0)),
    "static friction below dynamic": (IA, ["material", "static_friction", "0.2"], lambda s, c: lambda: c.add_object(
        s, "new", builtin="cube_5cm", friction=(0.2, 0.5))),
    "mesh index out of range": (IA, ["geometry.mesh", "index 8"], lambda s, c: mesh(
        s, c, CUBE[0], np.vstack([CUBE[1], [[0, 1, 8]]]))),
    "empty mesh": (IA, ["geometry.mesh", "empty"], lambda s, c: mesh(s, c, np.zeros((0, 3)), np.zeros((0, 3)))),
    "vertices bytes not a multiple of 12": (IA, ["geometry.mesh.vertices", "100"], lambda s, c: raw_add_object(
        s, c, ODD_VERTICES)),
    "mesh file not uploaded": (IA, ["geometry.mesh_file", "missing.stl"], lambda s, c: lambda: c.add_object(
        s, "new", mesh_file="missing.stl", mass=1.0, inertia=UNIT_INERTIA)),
    "urdf mesh not uploaded": (IA, ["urdf", "missing.stl"], lambda s, c: robot(s, c, urdf(
        "bot", link("a", '<mesh filename="missing.stl"/>')))),
    "urdf does not parse": (IA, ["urdf"], lambda s, c: robot(s, c, "<robot name='bot'><link name='a'>")),
    "urdf joint cycle": (IA, ["urdf", "cycle"], lambda s, c: robot(s, c, urdf(
        "bot", link("a"), link("b"), joint("ab", "a", "b"), joint("ba", "b", "a")))),
    "urdf missing parent link": (IA, ["urdf", "ghost"], lambda s, c: robot(s, c, urdf(
        "bot", link("a"), joint("j", "ghost", "a")))),
    "duplicate object name": (EXISTS, ["name", "cube"], lambda s, c: box(s, c, name="cube")),
    "object named like a robot": (EXISTS, ["pg70"], lambda s, c: box(s, c, name="pg70")),
    "duplicate robot name": (EXISTS, ["pg70"], lambda s, c: lambda: c.add_robot(s, "pg70", builtin="schunk_pg70")),
    "bad object name": (IA, ["name", "bad name!"], lambda s, c: box(s, c, name="bad name!")),
    "too long object name": (IA, ["name"], lambda s, c: box(s, c, name="x" * 65)),
    "unknown builtin object": (NOT_FOUND, ["no_such_model"], lambda s, c: lambda: c.add_object(
        s, "new", builtin="no_such_model")),
    "unknown builtin robot": (NOT_FOUND, ["no_such_model"], lambda s, c: lambda: c.add_robot(
        s, "bot", builtin="no_such_model")),
    "remove a robot link": (FAILED, ["pg70/finger_left"], lambda s, c: lambda: c.remove_body(s, "pg70/finger_left")),
    "remove an unknown id": (NOT_FOUND, ["nope"], lambda s, c: lambda: c.remove_body(s, "nope")),
}


@pytest.fixture
def world(client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, 0.775, 1, 0, 0, 0])
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70", base_pose=[0, 0, 1.0, 0, 1, 0, 0])
    return scene_id


@pytest.mark.parametrize("case", list(CASES))
def test_rejected(client, world, case):
    code, fragments, make = CASES[case]
    assert_rejected(client, world, code, fragments, make(world, client))


def test_triangle_and_body_limits(start_server):
    server = start_server("--max-triangles-per-mesh=100", "--max-bodies-per-scene=2")
    sphere = meshes.uv_sphere(0.05, 11, 10)
    assert len(sphere[1]) == 200
    with graspsim.connect(server.address) as c:
        sid = c.create_scene("limits").id
        assert_rejected(c, sid, EXHAUSTED, ["200", "100"], mesh(sid, c, *sphere))
        c.add_object(sid, "small", mesh=meshes.uv_sphere(0.05, 6, 10), mass=0.1)
        c.add_object(sid, "second", sphere=0.05, mass=0.1)
        assert_rejected(c, sid, EXHAUSTED, ["2"], box(sid, c, name="third"))
        assert_rejected(c, sid, EXHAUSTED, ["2"], lambda: c.add_robot(sid, "pg70", builtin="schunk_pg70"))
        c.remove_body(sid, "second")
        assert_rejected(c, sid, EXHAUSTED, ["2"], lambda: c.add_robot(sid, "pg70", builtin="schunk_pg70"))
        c.add_object(sid, "third", sphere=0.05, mass=0.1)


REGRESSIONS = __import__("pathlib").Path(__file__).resolve().parents[1] / "fuzz" / "regressions"


@pytest.mark.parametrize("name", ["mesh_ply_unterminated_header", "mesh_ply_face_count_abort"])
def test_mesh_file_that_crashes_the_parser(client, world, name):
    """Files on which Assimp itself crashes or aborts (found by tests/fuzz/mesh_fuzz.cpp; the first byte of the
    fuzz input picked the extension): the request fails naming the file, the server and the scene go on."""
    data = (REGRESSIONS / name).read_bytes()[1:]
    client.upload_file(world, "hostile.ply", data)
    assert_rejected(client, world, IA, ["geometry.mesh_file", "hostile.ply", "could not be parsed"],
                    lambda: client.add_object(world, "new", mesh_file="hostile.ply", mass=1.0, inertia=UNIT_INERTIA))
    assert client.get_body_poses(world)  # still serving
