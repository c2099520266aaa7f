"""Scenes survive restarts and crashes (docs/durability.md): a server restarted on the same --data-dir, after
SIGTERM or kill -9, serves exactly what was acknowledged before; a deleted scene stays deleted; a rejected upload
is never stored; a damaged database stops the start with its path and is left as it was; and a short version
of the crash benchmark (tests/bench/crash.py) loses nothing acknowledged and shows nothing half-written."""
import hashlib
import subprocess
import sys
from pathlib import Path

import grpc
import numpy as np

import graspsim
from graspsim import meshes
from _support import IA, cube_stl, expect_error, header_for, raw_upload, two_link_urdf
from conftest import ServerProcess, server_binary

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
import crash  # noqa: E402  (tests/bench/crash.py)


def restart(server: ServerProcess, data_dir: Path, tmp_path: Path, kill: bool) -> ServerProcess:
    """Stops the server (SIGTERM, or kill -9), then starts a new one on the same data directory."""
    if kill:
        server.process.kill()
        server.process.wait()
    else:
        assert server.stop() == 0
    return ServerProcess([f"--data-dir={data_dir}"], tmp_path)


def everything(client, scene_id: str) -> dict:
    """All a client can read of a scene."""
    return {"scene": client.get_scene(scene_id, include_geometry=True),   # dataclasses: == compares every value
            "params": client.get_simulation_params(scene_id),
            "poses": {k: (tuple(v.position), tuple(v.orientation)) for k, v in client.get_body_poses(scene_id).items()},
            "joints": client.get_joint_positions(scene_id)}


def build(client) -> list:
    """Three scenes: one with every kind of edit, one empty, one deleted; returns the ids of the two kept."""
    full = client.create_scene("everything").id
    stl = meshes.to_stl(*meshes.uv_sphere(0.03, 40, 60))
    client.upload_file(full, "meshes/ball.stl", stl, chunk_size=16 << 10)
    client.upload_file(full, "arm.stl", cube_stl(0.04))
    client.add_object(full, "ball", mesh_file="meshes/ball.stl", mass=0.2, inertia=np.eye(3) * 1e-4,
                      pose=[0.3, 0, 0.05, 1, 0, 0, 0])
    client.add_object(full, "table", builtin="table")
    client.add_object(full, "cube", builtin="cube_5cm", pose=[0, 0, 0.8, 1, 0, 0, 0])
    client.add_object(full, "temporary", sphere=0.01, mass=0.01)
    client.add_robot(full, "pg70", builtin="schunk_pg70", base_pose=[0, 0, 1.0, 0, 1, 0, 0])
    client.add_robot(full, "arm", urdf=two_link_urdf("arm.stl"), base_pose=[1, 0, 0, 1, 0, 0, 0])
    client.remove_body(full, "temporary")
    client.set_simulation_params(full, time_step=5e-4, gravity=[0, 0, -3.7])
    client.set_body_poses(full, {"cube": [0.01, 0.02, 0.9, 1, 0, 0, 0]})
    client.set_joint_positions(full, {"arm/shoulder": 0.3, "pg70/finger_left_joint": 0.02})
    client.set_actuator(full, "pg70/finger_left_joint", "position", 0.01)
    client.step_simulation(full, 0.1)
    empty = client.create_scene("empty").id
    gone = client.create_scene("deleted").id
    client.upload_file(gone, "x.bin", b"x" * 1000)
    client.delete_scene(gone)
    return [full, empty], gone


def check_restart(tmp_path, kill: bool):
    data_dir = tmp_path / "data"
    server = ServerProcess([f"--data-dir={data_dir}"], tmp_path)
    with graspsim.connect(server.address) as client:
        kept, gone = build(client)
        before = {scene_id: everything(client, scene_id) for scene_id in kept}
        summaries = client.list_scenes()
    server = restart(server, data_dir, tmp_path, kill)
    try:
        with graspsim.connect(server.address) as client:
            assert client.list_scenes() == summaries  # ids, names, counts, revisions, times
            for scene_id in kept:
                assert everything(client, scene_id) == before[scene_id], scene_id
            with expect_error(grpc.StatusCode.NOT_FOUND, gone):
                client.get_scene(gone)
            # The restored scene goes on like the original: it simulates on from its time, and new scenes get
            # new ids (never the deleted scene's).
            t0 = next(s.time for s in summaries if s.id == kept[0])
            assert abs(client.step_simulation(kept[0], 0.05).time - (t0 + 0.05)) < 1e-9
            assert client.create_scene("after").id not in {gone, *kept}
    finally:
        assert server.stop() == 0


def test_restart_after_sigterm_serves_the_same_scenes(tmp_path):
    check_restart(tmp_path, kill=False)


def test_restart_after_kill_9_serves_every_acknowledged_write(tmp_path):
    check_restart(tmp_path, kill=True)


def test_a_rejected_upload_is_never_stored(tmp_path):
    data_dir = tmp_path / "data"
    server = ServerProcess([f"--data-dir={data_dir}"], tmp_path)
    with graspsim.connect(server.address) as client:
        scene_id = client.create_scene("uploads").id
        good = b"\x01" * 300_000
        client.upload_file(scene_id, "good.bin", good, chunk_size=64 << 10)
        bad = b"\x02" * 300_000
        header = header_for(scene_id, "bad.bin", bad, sha256=hashlib.sha256(b"other").hexdigest())
        with expect_error(IA, "header.sha256"):
            raw_upload(client, header, bad, 64 << 10)
    server = restart(server, data_dir, tmp_path, kill=True)
    try:
        with graspsim.connect(server.address) as client:
            files = {f.path: (f.size, f.sha256) for f in client.get_scene(scene_id).files}
            assert files == {"good.bin": (len(good), hashlib.sha256(good).hexdigest())}
    finally:
        assert server.stop() == 0


def test_a_damaged_database_stops_the_start_naming_it_and_is_kept(tmp_path):
    data_dir = tmp_path / "data"
    data_dir.mkdir()
    database = data_dir / "scenes.sqlite"
    garbage = bytes(range(256)) * 64
    database.write_bytes(garbage)
    result = subprocess.run([str(server_binary()), "--listen=127.0.0.1:0", "--http-listen=off",
                             f"--data-dir={data_dir}"], capture_output=True, text=True, timeout=60)
    assert result.returncode == 1, result
    output = result.stdout + result.stderr
    assert "cannot start" in output and str(database) in output, output
    assert database.read_bytes() == garbage  # never deleted nor rewritten


def test_data_dir_off_keeps_scenes_in_memory_only(tmp_path):
    server = ServerProcess(["--data-dir=off"], tmp_path)
    with graspsim.connect(server.address) as client:
        client.create_scene("volatile")
    assert server.stop() == 0
    server = ServerProcess(["--data-dir=off"], tmp_path)
    try:
        with graspsim.connect(server.address) as client:
            assert client.list_scenes() == []
    finally:
        assert server.stop() == 0


def test_crash_short():
    """10 seeded kill -9 iterations of the crash benchmark: nothing acknowledged lost, nothing partial."""
    figures = crash.crash_iterations(10, seed=3, group=5)
    assert figures["iterations"] == 10
    assert figures["acknowledged_lost"] == 0, figures
    assert figures["partial_visible"] == 0, figures
    # The workload really wrote and the checks really looked (a run that did nothing would pass vacuously).
    writes = figures["acknowledged_writes"]
    for kind in ("create", "upload", "poses", "joints", "step"):
        assert writes.get(kind, 0) > 0, writes
    assert figures["scenes_checked"] >= 10
