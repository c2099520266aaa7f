"""ExportScene / ImportScene (issue 23): a scene moved to another server by archive is the same scene."""
import numpy as np
import pytest

import graspsim


def test_a_scene_moves_to_another_server_whole(client, start_server, tmp_path):
    sid = client.create_scene("to move").id
    try:
        client.add_robot(sid, "gripper", builtin="schunk_pg70", base_pose=[0, 0, 0.3, 1, 0, 0, 0])
        client.add_object(sid, "table", builtin="table")
        client.add_object(sid, "cube", builtin="cube_5cm", pose=[0.01, 0.02, 0.9, 1, 0, 0, 0])
        client.step_simulation(sid, steps=50)
        archive = client.export_scene(sid)
        original = client.get_scene(sid, include_geometry=True)
        poses = client.get_body_poses(sid)
        joints = client.get_joint_positions(sid)

        other = start_server(f"--data-dir={tmp_path / 'other'}")
        with graspsim.connect(other.address) as there:
            assert there.import_scene(archive).id == sid, "the archive's id by default"
            assert there.import_scene(archive, scene_id="copy").id == "copy"
            with pytest.raises(graspsim.AlreadyExists, match=sid):
                there.import_scene(archive)
            moved = there.get_scene(sid, include_geometry=True)
            assert moved.summary.name == "to move"
            assert [b.id for b in moved.bodies] == [b.id for b in original.bodies]
            for key, pose in there.get_body_poses(sid).items():
                np.testing.assert_array_equal(pose.position, poses[key].position)
                np.testing.assert_array_equal(pose.orientation, poses[key].orientation)
            assert there.get_joint_positions(sid) == joints
            # The copy simulates on exactly as the original does.
            client.step_simulation(sid, steps=20)
            there.step_simulation(sid, steps=20)
            a, b = client.get_body_poses(sid, ["cube"])["cube"], there.get_body_poses(sid, ["cube"])["cube"]
            np.testing.assert_array_equal(a.position, b.position)
        other.stop()
        restarted = start_server(f"--data-dir={tmp_path / 'other'}")  # the import was journaled
        with graspsim.connect(restarted.address) as there:
            assert {s.id for s in there.list_scenes()} == {sid, "copy"}
    finally:
        client.delete_scene(sid)


def test_a_bad_archive_is_refused_and_leaves_nothing(client):
    before = {s.id for s in client.list_scenes()}
    with pytest.raises(graspsim.InvalidArgument, match="data: not a graspsim scene archive"):
        client.import_scene(b"GSSCENE\\x01 certainly not", scene_id="bad")
    sid = client.create_scene("small").id
    try:
        archive = client.export_scene(sid)
        with pytest.raises(graspsim.InvalidArgument, match="truncated"):
            client.import_scene(archive[:-3], scene_id="cut")
        with pytest.raises(graspsim.InvalidArgument, match="scene_id"):
            client.import_scene(archive, scene_id="no/slashes")
        with pytest.raises(graspsim.NotFound, match="no-such-scene"):
            client.export_scene("no-such-scene")
        assert {s.id for s in client.list_scenes()} == before | {sid}
    finally:
        client.delete_scene(sid)
