"""graspsim.batch (issue 23): grasp databases and other jobs on a pool of Ray actors, each with a graspsim-server of
its own. A small job (three meshes and a bad one, two hands, 48 candidates each) on 2 workers equals what one plain
Client against one server answers with the same seed; killing an actor and a worker's server mid-job loses no task
and duplicates none; a second run skips what is written; shape completion and map_scenes likewise."""
import os
import shutil
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

# The local Ray of these tests on loopback only: on Linux Ray binds its GCS and raylets to the node's address
# unless this is off (read when ray is imported; the actors' worker processes inherit it).
os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
import ray  # noqa: E402
import trimesh

from graspsim.batch import (ServerActor, TaskError, complete_shapes, map_scenes, mesh_sha256, plan_grasp_database,
                            read_dataset)
from graspsim.testing import partial_view

from _support import VIEW_INTRINSICS, cylinder_view
from conftest import server_binary

HANDS = ["schunk_pg70", "schunk_sdh2"]
PARAMS = {"max_candidates": 48, "max_grasps": 10}
SEED = 7
BAD = ("bad_index", np.zeros((3, 3)), np.array([[0, 1, 5]]))   # triangle index out of range: the server refuses it
TIMING = {"task_seconds"}   # the only columns that differ between two runs of the same job


@pytest.fixture(scope="module")
def ray_local():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


@pytest.fixture(scope="module")
def meshes(tmp_path_factory):
    """A box as an STL file (the path loader), a cylinder and a sphere as arrays, and the bad mesh."""
    folder = tmp_path_factory.mktemp("meshes")
    box = folder / "box.stl"
    trimesh.creation.box((0.05, 0.06, 0.08)).export(box)
    cylinder = trimesh.creation.cylinder(0.03, 0.1, sections=24)
    sphere = trimesh.creation.icosphere(2, 0.035)
    return [box, ("cylinder", cylinder.vertices, cylinder.faces), ("sphere", sphere.vertices, sphere.faces), BAD]


def job(meshes, out, **kwargs):
    return plan_grasp_database(meshes, HANDS, out_dir=out, params=PARAMS, seed=SEED, workers=2, progress=False,
                               server=str(server_binary()), **kwargs)


def rows(dataset):
    table = read_dataset(dataset).sort_by([("key", "ascending"), ("grasp_index", "ascending")])
    return table.drop_columns(sorted(TIMING)).to_pylist()


@pytest.fixture(scope="module")
def plain_run(ray_local, meshes, tmp_path_factory):
    out = tmp_path_factory.mktemp("plain")
    return job(meshes, out), out / "grasps"


def test_database_equals_one_plain_server(plain_run, meshes, client):
    summary, dataset = plain_run
    assert (summary.tasks, summary.done, summary.errors, summary.skipped, summary.retried) == (8, 8, 2, 0, 0)
    table = read_dataset(dataset).to_pylist()
    for source in meshes[:3]:
        if isinstance(source, Path):
            mesh = trimesh.load(source, force="mesh")
            name, vertices, triangles = source.stem, mesh.vertices, mesh.faces
        else:
            name, vertices, triangles = source
        for hand in HANDS:
            ref = client.plan_grasps(hand, mesh=(vertices, triangles), seed=SEED, recompute=True, progress=False,
                                     **PARAMS)
            got = sorted((r for r in table if r["mesh"] == name and r["hand"] == hand), key=lambda r: r["grasp_index"])
            got = {column: [r[column] for r in got] for column in got[0]}
            assert got["mesh_sha256"][0] == ref.mesh_sha256 == mesh_sha256(np.asarray(vertices), np.asarray(triangles))
            assert got["set_id"][0] == ref.set_id and got["task_candidates"][0] == ref.candidates == 48
            assert got["task_force_closure"][0] == ref.force_closure
            assert len(ref.grasps) > 0 and got["grasp_index"] == list(range(len(ref.grasps)))
            assert got["epsilon"] == ref.grasps["epsilon"].tolist()
            np.testing.assert_allclose(np.hstack([got["position"], got["quaternion"]]), ref.grasps["hand_pose"],
                                       rtol=0, atol=1e-9)
            np.testing.assert_allclose(got["joint_positions"], ref.grasps["joint_positions"], rtol=0, atol=1e-9)
            assert [len(p) for p in got["contact_points"]] == ref.grasps["contact_count"].tolist()
    bad = [r for r in table if r["mesh"] == "bad_index"]
    assert len(bad) == 2 and [r["grasp_index"] for r in bad] == [None, None]
    assert all("out of range for 3 vertices" in r["error"] for r in bad)
    assert all(r["error"] is None for r in table if r["mesh"] != "bad_index")


def _kill_mid_job(dataset: Path, record: list):
    """Once 1 task is written: ray.kill one worker actor; once 3 are: kill -9 one worker's graspsim-server."""
    def written():
        return len(list(dataset.glob("*.parquet"))) if dataset.is_dir() else 0

    deadline = time.monotonic() + 60
    while written() < 1 and time.monotonic() < deadline:
        time.sleep(0.01)
    names = sorted(ray.util.list_named_actors())
    if names:
        ray.kill(ray.get_actor(names[0]), no_restart=True)
        record.append(("actor", names[0]))
    while written() < 3 and time.monotonic() < deadline:
        time.sleep(0.01)
    for pid in _batch_server_pids():
        os.kill(pid, signal.SIGKILL)
        record.append(("server", pid))
        break


def _batch_server_pids():
    pids = []
    for entry in Path("/proc").iterdir():
        try:
            argv = (entry / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if argv[0].endswith(b"graspsim-server") and any(b"/graspsim-batch-" in a for a in argv):
            pids.append(int(entry.name))
    return pids


def test_killed_workers_lose_no_task_and_duplicate_none(plain_run, meshes, tmp_path):
    dataset, killed = tmp_path / "grasps", []
    killer = threading.Thread(target=_kill_mid_job, args=(dataset, killed))
    killer.start()
    summary = job(meshes, tmp_path)
    killer.join()
    assert [kind for kind, _ in killed] == ["actor", "server"]
    assert summary.done == summary.tasks == 8 and summary.retried >= 1 and summary.replaced == summary.retried
    # One file per task, each key's rows once: the same rows as the run nobody disturbed.
    assert len(list(dataset.glob("*.parquet"))) == 8 and not list(dataset.glob(".*"))
    assert rows(dataset) == rows(plain_run[1])
    time.sleep(0.5)
    assert _batch_server_pids() == [], "a worker's server outlived the job"


def test_rerun_skips_written_tasks(plain_run, meshes, tmp_path):
    dataset = tmp_path / "grasps"
    job(meshes, tmp_path)
    again = job(meshes, tmp_path)
    assert (again.skipped, again.done, again.workers) == (8, 0, 0)
    victim = sorted(dataset.glob("*.parquet"))[0]
    victim.unlink()
    once_more = job(meshes, tmp_path)
    assert (once_more.skipped, once_more.done) == (7, 1) and victim.exists()
    retry = job(meshes, tmp_path, retry_errors=True)   # the bad mesh's two error rows are planned again
    assert (retry.skipped, retry.done, retry.errors) == (6, 2, 2)
    assert rows(dataset) == rows(plain_run[1])


def test_actor_death_stops_its_server(ray_local):
    actor = ServerActor.remote(str(server_binary()))
    info = ray.get(actor.info.remote())
    assert info["compute_threads"] == 1 and Path(info["data_dir"]).is_dir()
    ray.kill(actor)
    deadline = time.monotonic() + 10
    while Path(f"/proc/{info['server_pid']}").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not Path(f"/proc/{info['server_pid']}").exists() or \
        "Z" in Path(f"/proc/{info['server_pid']}/stat").read_text().split()[2]
    shutil.rmtree(info["data_dir"], ignore_errors=True)   # a killed actor cannot remove its temporary dir


def test_map_scenes_in_input_order(ray_local):
    def scene_name(client, item):
        if item == "boom":
            raise ValueError("no such item")
        scene = client.create_scene(item)
        return scene.name, len(client.list_scenes())

    items = ["a", "b", "boom", "c", "d"]
    results = map_scenes(scene_name, items, workers=2, server=str(server_binary()), progress=False,
                         return_exceptions=True)
    assert [r[0] for r in results if not isinstance(r, TaskError)] == ["a", "b", "c", "d"]
    assert isinstance(results[2], TaskError) and "ValueError: no such item" in str(results[2])
    with pytest.raises(TaskError, match="item 2"):
        map_scenes(scene_name, items, workers=1, server=str(server_binary()), progress=False)


def test_complete_shapes_rows(ray_local, client, tmp_path):
    camera, depth, mask = cylinder_view()
    points = partial_view.depth_to_points(depth, camera, *VIEW_INTRINSICS, mask=mask)
    views = [{"name": "cylinder_depth", "camera_pose": camera, "depth": depth, "intrinsics": VIEW_INTRINSICS,
              "mask": mask, "table_pose": [0, 0, 0, 1, 0, 0, 0]},
             ("cylinder_points", camera, points), ("two_points", camera, points[:2])]
    summary = complete_shapes(views, out_dir=tmp_path, params={"orientations": 1}, workers=2, progress=False,
                              server=str(server_binary()))
    assert (summary.tasks, summary.done, summary.errors) == (3, 3, 1)
    table = {r["view"]: r for r in pq.read_table(tmp_path / "shapes").to_pylist()}
    ref = client.complete_shape(camera, points=points, orientations=1)
    got = table["cylinder_points"]
    assert got["error"] is None and got["vertices"] == len(ref.vertices) and got["triangles"] == len(ref.triangles)
    assert got["mesh_vertices"] == ref.vertices.astype("<f4").tobytes()
    assert 0 < got["volume"] < 1e-3 and table["cylinder_depth"]["volume"] > 0
    assert table["two_points"]["error"] and table["two_points"]["vertices"] is None
