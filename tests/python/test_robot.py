"""Robots: the built-in Schunk PG70 (mimic fingers, tactile pads) and URDFs with uploaded or inline meshes."""
import numpy as np
import pytest

import graspsim
from _support import cube_stl, two_link_urdf

LEFT, RIGHT = "pg70/finger_left_joint", "pg70/finger_right_joint"
BASE_POSE = graspsim.Pose([0.2, -0.1, 1.0], graspsim.quaternion_about_axis([1, 0.3, 0.2], 2.5))


@pytest.fixture
def pg70(client, scene_id):
    return client.add_robot(scene_id, "pg70", builtin="schunk_pg70", base_pose=BASE_POSE)


def test_pg70_structure(client, scene_id, pg70):
    assert pg70.robot.id == "pg70" and pg70.robot.source == "builtin:schunk_pg70"
    assert pg70.robot.base_body == "pg70/base_link"
    bodies = {"pg70/base_link", "pg70/finger_left", "pg70/finger_right"}
    assert set(pg70.robot.body_ids) == bodies == {b.id for b in pg70.bodies}
    assert set(pg70.robot.joint_ids) == {LEFT, RIGHT}
    scene = client.get_scene(scene_id)
    assert {b.id for b in scene.bodies} == bodies
    assert all(b.motion == "articulated" and b.robot_id == "pg70" for b in scene.bodies)
    joints = {j.id: j for j in scene.joints}
    assert joints[LEFT].type == "prismatic"
    assert (joints[LEFT].lower, joints[LEFT].upper) == pytest.approx((0.0, 0.035))
    assert joints[RIGHT].mimic.joint_id == LEFT and joints[RIGHT].mimic.multiplier == pytest.approx(1.0)
    pads = {a.id: a for a in scene.tactile_arrays}
    assert set(pads) == {"pg70/pad_left", "pg70/pad_right"}
    for pad in pads.values():
        assert (pad.rows, pad.cols) == (14, 6) and pad.pitch == pytest.approx(0.0034)
        # The built-in DSA 9205 pads: flat, one sensing element per texel at its centre.
        assert (pad.subdivision, pad.elements, pad.bend_radius_x, pad.bend_radius_y) == (1, "vertices", 0, 0)
        assert pad.body_id in {"pg70/finger_left", "pg70/finger_right"}
    assert scene.summary.robot_count == 1 and [r.id for r in scene.robots] == ["pg70"]
    base = {b.id: b for b in scene.bodies}["pg70/base_link"].pose
    np.testing.assert_allclose(base.as_array(), BASE_POSE.as_array(), atol=1e-12)


def test_mimic_fingers_move_symmetrically(client, scene_id, pg70):
    fingers = ["pg70/finger_left", "pg70/finger_right"]
    client.set_joint_positions(scene_id, {LEFT: 0.0})
    closed = client.get_body_poses(scene_id, fingers)
    client.set_joint_positions(scene_id, {LEFT: 0.02})
    assert client.get_joint_positions(scene_id, [LEFT, RIGHT]) == pytest.approx({LEFT: 0.02, RIGHT: 0.02}, abs=1e-12)
    opened = client.get_body_poses(scene_id, fingers)
    rotation = BASE_POSE.rotation_matrix()
    moves = [rotation.T @ (opened[f].position - closed[f].position) for f in fingers]  # in the gripper frame
    sign = np.sign(moves[0][1])
    np.testing.assert_allclose(moves[0], [0, sign * 0.02, 0], atol=1e-9)
    np.testing.assert_allclose(moves[1], [0, -sign * 0.02, 0], atol=1e-9)
    for f in fingers:
        np.testing.assert_allclose(opened[f].orientation, closed[f].orientation, atol=1e-12)


def test_remove_robot_removes_links_joints_pads(client, scene_id, pg70):
    client.add_object(scene_id, "cube", builtin="cube_5cm")
    removed = client.remove_body(scene_id, "pg70")
    assert set(removed) == {"pg70/base_link", "pg70/finger_left", "pg70/finger_right"}
    scene = client.get_scene(scene_id)
    assert [b.id for b in scene.bodies] == ["cube"]
    assert not scene.joints and not scene.robots and not scene.tactile_arrays


def test_urdf_with_uploaded_mesh(client, scene_id):
    stl = cube_stl()
    info = client.upload_file(scene_id, "meshes/cube.stl", stl)
    assert (info.path, info.size) == ("meshes/cube.stl", len(stl))
    added = client.add_robot(scene_id, "arm", urdf=two_link_urdf("meshes/cube.stl"), base_pose=[0, 0, 0.5, 1, 0, 0, 0])
    assert added.robot.source == "urdf" and added.robot.base_body == "arm/base"
    assert set(added.robot.joint_ids) == {"arm/shoulder"}
    bodies = {b.id: b for b in client.get_scene(scene_id).bodies}
    assert bodies["arm/arm"].triangle_count == 12 and bodies["arm/base"].triangle_count == 0
    assert "meshes/cube.stl" in {f.path for f in client.get_scene(scene_id).files}


def test_urdf_with_inline_file(client, scene_id):
    added = client.add_robot(scene_id, "arm", urdf=two_link_urdf("meshes/inline.stl"),
                             files={"meshes/inline.stl": cube_stl(0.02)})
    assert {b.id: b.triangle_count for b in added.bodies} == {"arm/base": 0, "arm/arm": 12}
    client.set_joint_positions(scene_id, {"arm/shoulder": 0.5})
    assert client.get_joint_positions(scene_id) == pytest.approx({"arm/shoulder": 0.5})
