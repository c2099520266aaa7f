"""SetBodyPoses / SetJointPositions: round trips, normalisation, all-or-nothing batches, robot rules."""
import grpc
import numpy as np
import pytest

import graspsim
from _support import IA, assert_rejected

NOT_FOUND, FAILED = grpc.StatusCode.NOT_FOUND, grpc.StatusCode.FAILED_PRECONDITION
LEFT, RIGHT = "pg70/finger_left_joint", "pg70/finger_right_joint"
POSE_A = graspsim.Pose([0.3, 0.1, 0.9], graspsim.quaternion_about_axis([0, 1, 1], 0.4))


@pytest.fixture
def world(client, scene_id):
    """Two free boxes, a static table and a PG70."""
    client.add_object(scene_id, "a", box=(0.05, 0.05, 0.05), mass=0.1)
    client.add_object(scene_id, "b", box=(0.05, 0.05, 0.05), mass=0.1, pose=[0.5, 0, 0.8, 1, 0, 0, 0])
    client.add_object(scene_id, "table", builtin="table")
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70", base_pose=[0, 0, 1.0, 0, 1, 0, 0])
    return scene_id


def test_pose_round_trip_and_revision(client, world):
    revision = client.get_scene(world).summary.revision
    new_revision = client.set_body_pose(world, "a", POSE_A)
    assert new_revision > revision and client.get_scene(world).summary.revision == new_revision
    poses = client.get_body_poses(world, ["a"])
    assert list(poses) == ["a"]
    np.testing.assert_allclose(poses["a"].as_array(), POSE_A.as_array(), atol=1e-12)
    assert set(client.get_body_poses(world)) == {"a", "b", "table", "pg70/base_link", "pg70/finger_left",
                                                 "pg70/finger_right"}


def test_near_unit_quaternion_is_normalised(client, world):
    q = np.array([1.0, 0.02, -0.01, 0.03])
    q *= (1 + 5e-4) / np.linalg.norm(q)
    client.set_body_pose(world, "a", ([0, 0, 1], q))
    held = client.get_body_poses(world, ["a"])["a"].orientation
    np.testing.assert_allclose(held, q / np.linalg.norm(q), atol=1e-12)


def test_static_body_can_be_posed(client, world):
    client.set_body_pose(world, "table", [1, 2, 0, 1, 0, 0, 0])
    np.testing.assert_allclose(client.get_body_poses(world, ["table"])["table"].position, [1, 2, 0])


@pytest.mark.parametrize("bad, code, fragments", [
    ({"nope": POSE_A}, NOT_FOUND, ["nope"]),
    ({"b": [np.nan, 0, 0, 1, 0, 0, 0]}, IA, ["poses[1].pose.position", "nan"]),
    ({"b": [0, 0, 0, 0.5, 0, 0, 0]}, IA, ["poses[1].pose.orientation", "0.5"]),
    ({"pg70/finger_left": POSE_A}, FAILED, ["pg70/finger_left"]),
])
def test_bad_pose_batch_changes_nothing(client, world, bad, code, fragments):
    batch = {"a": POSE_A, **bad}
    assert_rejected(client, world, code, fragments, lambda: client.set_body_poses(world, batch))


def test_robot_id_and_base_body_move_whole_robot(client, world):
    client.set_joint_positions(world, {LEFT: 0.01})
    before = client.get_body_poses(world)
    for target in ("pg70", "pg70/base_link"):
        client.set_body_pose(world, target, POSE_A)
        after = client.get_body_poses(world)
        np.testing.assert_allclose(after["pg70/base_link"].as_array(), POSE_A.as_array(), atol=1e-12)
        for link in ("pg70/finger_left", "pg70/finger_right"):
            relative_before = np.linalg.inv(before["pg70/base_link"].matrix()) @ before[link].matrix()
            relative_after = np.linalg.inv(after["pg70/base_link"].matrix()) @ after[link].matrix()
            np.testing.assert_allclose(relative_after, relative_before, atol=1e-9)
        np.testing.assert_allclose(after["a"].as_array(), before["a"].as_array())
        client.set_body_pose(world, "pg70", before["pg70/base_link"])


def test_joint_round_trip_and_mimic(client, world):
    client.set_joint_positions(world, {LEFT: 0.035})
    assert client.get_joint_positions(world) == pytest.approx({LEFT: 0.035, RIGHT: 0.035}, abs=1e-12)
    assert client.get_joint_positions(world, [RIGHT]) == pytest.approx({RIGHT: 0.035}, abs=1e-12)


@pytest.mark.parametrize("value, code, fragments", [
    (0.05, IA, [LEFT, "0.05"]),
    (-0.001, IA, [LEFT, "-0.001"]),
    (float("nan"), IA, [LEFT, "nan"]),
])
def test_bad_joint_value_changes_nothing(client, world, value, code, fragments):
    client.set_joint_positions(world, {LEFT: 0.01})
    assert_rejected(client, world, code, fragments, lambda: client.set_joint_positions(world, {LEFT: value}))
    assert client.get_joint_positions(world, [LEFT]) == pytest.approx({LEFT: 0.01})


def test_mimic_joint_cannot_be_set(client, world):
    batch = {LEFT: 0.02, RIGHT: 0.01}
    assert_rejected(client, world, IA, [RIGHT, LEFT], lambda: client.set_joint_positions(world, batch))


def test_unknown_joint_in_batch_changes_nothing(client, world):
    batch = {LEFT: 0.02, "pg70/nope": 0.0}
    assert_rejected(client, world, NOT_FOUND, ["pg70/nope"], lambda: client.set_joint_positions(world, batch))


def test_get_unknown_ids_not_found(client, world):
    for call in (lambda: client.get_body_poses(world, ["nope"]), lambda: client.get_joint_positions(world, ["nope"])):
        with pytest.raises(graspsim.GraspsimError) as info:
            call()
        assert info.value.code == NOT_FOUND and "nope" in info.value.message, str(info.value)
