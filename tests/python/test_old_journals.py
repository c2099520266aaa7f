"""Scenes stored by an earlier release still open (issue 24): tests/data/journal-v1 holds the scene store and the
ExportScene archive that the server of commit b98e4f9 wrote for a scene with every kind of edit, whose journal
stored serialized v1 requests (scripts/make_journal_fixture.py made them). Today's server journals typed edit
records (server/src/edits/edit_codec.h) and reads the old ops through rpc's LegacyEdit: the scene it restores must
be exactly what the old server served — every body, geometry byte, material, parameter, pose and joint — and new
edits on it must survive a restart beside the old ones."""
import json
import shutil
import sys
from pathlib import Path

import grpc
import pytest

from conftest import ServerProcess
from graspsim.v1 import common_pb2, scene_pb2, scene_pb2_grpc

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
from make_journal_fixture import SCENE, observed  # noqa: E402  (what the fixture recorded, read the same way)

FIXTURE = Path(__file__).resolve().parents[1] / "data" / "journal-v1"


def without(value, key: str):
    """`value` with every entry named `key` dropped, at any depth."""
    if isinstance(value, dict):
        return {k: without(v, key) for k, v in value.items() if k != key}
    if isinstance(value, list):
        return [without(v, key) for v in value]
    return value


def assert_holds(expected, actual, where: str = "") -> None:
    """Every field the old server reported is reported now with the same value (fields added since may appear)."""
    if isinstance(expected, dict):
        assert isinstance(actual, dict), where
        for key, value in expected.items():
            assert key in actual, f"{where}.{key} is missing"
            assert_holds(value, actual[key], f"{where}.{key}")
    elif isinstance(expected, list):
        assert isinstance(actual, list) and len(actual) == len(expected), f"{where}: {len(expected)} entries expected"
        for i, (e, a) in enumerate(zip(expected, actual)):
            assert_holds(e, a, f"{where}[{i}]")
    else:
        assert actual == expected, f"{where}: {actual!r}, the old server {expected!r}"


@pytest.fixture
def expected() -> dict:
    return json.loads((FIXTURE / "expected.json").read_text())


def test_the_fixture_is_what_it_says():
    """The store holds version-1 ops (serialized requests, no edit record header): else this test proves nothing."""
    import sqlite3
    with sqlite3.connect(FIXTURE / "scenes.sqlite") as db:
        ops = db.execute("SELECT kind, payload FROM scene_ops ORDER BY seq").fetchall()
    kinds = {kind for kind, _ in ops}
    assert kinds == {"UploadFile", "AddObject", "AddRobot", "RemoveBody", "SetSimulationParams"}
    assert not any(bytes(payload).startswith(b"GSEDIT") for _, payload in ops)


def test_a_stored_scene_of_the_old_release_opens_as_it_was(tmp_path, expected):
    data_dir = tmp_path / "scenes"
    data_dir.mkdir()
    shutil.copy(FIXTURE / "scenes.sqlite", data_dir / "scenes.sqlite")
    server = ServerProcess([f"--data-dir={data_dir}"], tmp_path)
    try:
        with grpc.insecure_channel(server.address) as channel:
            stub = scene_pb2_grpc.SceneServiceStub(channel)
            assert_holds(expected, observed(stub))
            # A new edit on the old scene is journaled as an edit record, after the old ops.
            stub.AddObject(scene_pb2.AddObjectRequest(
                scene_id=SCENE, name="new", pose=common_pb2.Pose(position=common_pb2.Vec3(z=1.5)),
                geometry=common_pb2.Geometry(box=common_pb2.Box(size=common_pb2.Vec3(x=0.02, y=0.02, z=0.02))),
                inertial=common_pb2.Inertial(mass=0.01, ixx=1e-6, iyy=1e-6, izz=1e-6)))
            before_restart = observed(stub)
    finally:
        assert server.stop() == 0
    server = ServerProcess([f"--data-dir={data_dir}"], tmp_path)
    try:
        with grpc.insecure_channel(server.address) as channel:
            after = observed(scene_pb2_grpc.SceneServiceStub(channel))
        assert after == before_restart
        assert "new" in [b["id"] for b in after["scene"]["bodies"]]
    finally:
        assert server.stop() == 0
    import sqlite3
    with sqlite3.connect(data_dir / "scenes.sqlite") as db:
        payloads = [bytes(p) for k, p in db.execute("SELECT kind, payload FROM scene_ops ORDER BY seq")]
    assert payloads[-1].startswith(b"GSEDIT\x02") and not payloads[-2].startswith(b"GSEDIT")


def test_an_archive_of_the_old_release_imports_as_it_was(tmp_path, expected):
    server = ServerProcess([], tmp_path)
    try:
        with grpc.insecure_channel(server.address) as channel:
            stub = scene_pb2_grpc.SceneServiceStub(channel)
            archive = (FIXTURE / "scene.gsscene").read_bytes()
            imported = stub.ImportScene(iter([scene_pb2.SceneArchiveChunk(data=archive)]))
            assert imported.summary.id == SCENE
            # An imported scene gets a revision above any its id had here; everything else is the old scene's.
            assert_holds(without(expected, "revision"), without(observed(stub), "revision"))
            exported = b"".join(c.data for c in stub.ExportScene(scene_pb2.ExportSceneRequest(scene_id=SCENE)))
            assert exported.count(b"GSEDIT\x02") == 12  # its model edits re-journaled as records; the upload as is
    finally:
        assert server.stop() == 0
