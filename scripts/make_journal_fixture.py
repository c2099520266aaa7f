#!/usr/bin/env python3
"""Writes a journal fixture: what a released graspsim-server stored for a scene that holds every kind of edit.

Usage: make_journal_fixture.py SERVER_BINARY OUT_DIR

Runs SERVER_BINARY on a fresh --data-dir, builds one scene through the raw v1 API (so the client library's own
changes cannot alter what is sent): an uploaded STL, objects from every shape source (box, sphere, cylinder,
inline mesh, mesh file, built-ins) with inertials and materials, a built-in robot and a URDF robot with an inline
mesh file, a removed body, new simulation parameters, poses, joints, an actuator and simulated steps. Then it
exports the scene (ExportScene), reads back everything a client can see of it, stops the server with SIGTERM and
writes to OUT_DIR:
  scenes.sqlite     the scene store, checkpointed into one file (no -wal beside it)
  scene.gsscene     the ExportScene archive
  expected.json     GetScene (with geometry), GetSimulationParams, GetBodyPoses and GetJointPositions as JSON
tests/python/test_old_journals.py opens these with today's server (issue 24: stored scenes still open after the
journal's format changed). tests/data/journal-v1 was written with the server of commit b98e4f9, whose journal
stored serialized v1 requests.
"""
import hashlib
import json
import shutil
import socket
import sqlite3
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import grpc
from google.protobuf import json_format

from graspsim.v1 import common_pb2, scene_pb2, scene_pb2_grpc

SCENE = "journal-v1"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def cube_stl(edge: float) -> bytes:
    """A closed cube, binary STL."""
    h = edge / 2
    v = [(x, y, z) for x in (-h, h) for y in (-h, h) for z in (-h, h)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    out = bytearray(80) + struct.pack("<I", len(faces))
    for f in faces:
        out += struct.pack("<3f", 0, 0, 0)
        for i in f:
            out += struct.pack("<3f", *v[i])
        out += b"\0\0"
    return bytes(out)


def tetrahedron() -> common_pb2.MeshData:
    vertices = [(0, 0, 0), (0.04, 0, 0), (0, 0.04, 0), (0, 0, 0.04)]
    triangles = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    return common_pb2.MeshData(vertices=b"".join(struct.pack("<3f", *p) for p in vertices),
                               triangles=b"".join(struct.pack("<3I", *t) for t in triangles))


def pose(x, y, z, w=1.0, qx=0.0, qy=0.0, qz=0.0) -> common_pb2.Pose:
    return common_pb2.Pose(position=common_pb2.Vec3(x=x, y=y, z=z),
                           orientation=common_pb2.Quaternion(w=w, x=qx, y=qy, z=qz))


def inertial(mass: float, i: float) -> common_pb2.Inertial:
    return common_pb2.Inertial(mass=mass, ixx=i, iyy=i, izz=i)


URDF = """<robot name="arm">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="upper"><inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0"
    iyz="0"/></inertial><collision><geometry><mesh filename="meshes/upper.stl"/></geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="10" velocity="1"/></joint>
</robot>"""


def build(stub) -> None:
    stub.CreateScene(scene_pb2.CreateSceneRequest(name="every edit", scene_id=SCENE))
    stl = cube_stl(0.04)
    header = scene_pb2.UploadFileHeader(scene_id=SCENE, path="meshes/cube.stl", total_size=len(stl),
                                        sha256=hashlib.sha256(stl).hexdigest())
    stub.UploadFile(iter([scene_pb2.UploadFileChunk(header=header, data=stl)]))
    add = stub.AddObject
    add(scene_pb2.AddObjectRequest(scene_id=SCENE, name="table", builtin="table"))
    add(scene_pb2.AddObjectRequest(scene_id=SCENE, name="cube", builtin="cube_5cm", pose=pose(0, 0, 0.8),
                                   material=common_pb2.Material(static_friction=0.9, dynamic_friction=0.7)))
    add(scene_pb2.AddObjectRequest(
        scene_id=SCENE, name="box", pose=pose(0.2, 0, 0.8, 0.9238795, 0, 0, 0.3826834),
        geometry=common_pb2.Geometry(box=common_pb2.Box(size=common_pb2.Vec3(x=0.05, y=0.06, z=0.07)),
                                     origin=pose(0, 0, 0.01)),
        inertial=inertial(0.3, 2e-4),
        material=common_pb2.Material(contact_stiffness=2e4, bristle_damping=20, stribeck_velocity=2e-3)))
    add(scene_pb2.AddObjectRequest(scene_id=SCENE, name="ball",
                                   geometry=common_pb2.Geometry(sphere=common_pb2.Sphere(radius=0.02)),
                                   import_options=common_pb2.ImportOptions(density=500), pose=pose(-0.2, 0, 0.8)))
    add(scene_pb2.AddObjectRequest(scene_id=SCENE, name="can", is_static=True, pose=pose(0, 0.3, 0.75),
                                   geometry=common_pb2.Geometry(
                                       cylinder=common_pb2.Cylinder(radius=0.03, length=0.1))))
    add(scene_pb2.AddObjectRequest(scene_id=SCENE, name="tetra", pose=pose(0, -0.3, 0.8),
                                   geometry=common_pb2.Geometry(mesh=tetrahedron(),
                                                                scale=common_pb2.Vec3(x=1, y=2, z=1)),
                                   inertial=inertial(0.05, 1e-5)))
    add(scene_pb2.AddObjectRequest(scene_id=SCENE, name="filed", pose=pose(0.3, 0.3, 0.8),
                                   geometry=common_pb2.Geometry(mesh_file="meshes/cube.stl",
                                                                scale=common_pb2.Vec3(x=1, y=1, z=0.5)),
                                   inertial=inertial(0.1, 3e-5)))
    add(scene_pb2.AddObjectRequest(scene_id=SCENE, name="temporary",
                                   geometry=common_pb2.Geometry(sphere=common_pb2.Sphere(radius=0.01)),
                                   inertial=inertial(0.01, 1e-7)))
    stub.AddRobot(scene_pb2.AddRobotRequest(scene_id=SCENE, name="pg70", builtin="schunk_pg70",
                                            base_pose=pose(0, 0, 1.0, 0, 1, 0, 0)))
    stub.AddRobot(scene_pb2.AddRobotRequest(
        scene_id=SCENE, name="arm", urdf=URDF, base_pose=pose(1, 0, 0),
        files=[common_pb2.InlineFile(path="meshes/upper.stl", data=cube_stl(0.03))]))
    stub.RemoveBody(scene_pb2.RemoveBodyRequest(scene_id=SCENE, id="temporary"))
    stub.SetSimulationParams(scene_pb2.SetSimulationParamsRequest(
        scene_id=SCENE, params=scene_pb2.SimulationParams(time_step=5e-4, substeps=2,
                                                          gravity=common_pb2.Vec3(z=-3.7),
                                                          integrator=scene_pb2.INTEGRATOR_SEMI_IMPLICIT_EULER)))
    stub.SetJointPositions(scene_pb2.SetJointPositionsRequest(scene_id=SCENE, positions=[
        common_pb2.JointPosition(joint_id="arm/shoulder", position=0.3)]))
    stub.StepSimulation(scene_pb2.StepSimulationRequest(scene_id=SCENE, steps=40))


def observed(stub) -> dict:
    """Everything a client can read of the scene, as JSON."""
    def as_json(message):
        return json_format.MessageToDict(message, preserving_proto_field_name=True)
    return {"scene": as_json(stub.GetScene(scene_pb2.GetSceneRequest(scene_id=SCENE, include_geometry=True))),
            "params": as_json(stub.GetSimulationParams(scene_pb2.GetSimulationParamsRequest(scene_id=SCENE))),
            "poses": as_json(stub.GetBodyPoses(scene_pb2.GetBodyPosesRequest(scene_id=SCENE))),
            "joints": as_json(stub.GetJointPositions(scene_pb2.GetJointPositionsRequest(scene_id=SCENE)))}


def main(binary: str, out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        port = free_port()
        server = subprocess.Popen([binary, f"--listen=127.0.0.1:{port}", f"--http-listen=127.0.0.1:{free_port()}",
                                   f"--data-dir={tmp}/scenes", f"--grasp-data-dir={tmp}/grasps"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
        try:
            channel = grpc.insecure_channel(f"127.0.0.1:{port}")
            grpc.channel_ready_future(channel).result(timeout=30)
            stub = scene_pb2_grpc.SceneServiceStub(channel)
            build(stub)
            archive = b"".join(c.data for c in stub.ExportScene(scene_pb2.ExportSceneRequest(scene_id=SCENE)))
            expected = observed(stub)
            channel.close()
        finally:
            server.terminate()
            assert server.wait(timeout=30) == 0, "the server did not stop cleanly"
        db = sqlite3.connect(f"{tmp}/scenes/scenes.sqlite")
        db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
        db.close()
        target = out / "scenes.sqlite"
        target.unlink(missing_ok=True)
        sqlite3.connect(f"{tmp}/scenes/scenes.sqlite").execute(f"VACUUM INTO '{target}'").connection.close()
    (out / "scene.gsscene").write_bytes(archive)
    (out / "expected.json").write_text(json.dumps(expected, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], Path(sys.argv[2]))
