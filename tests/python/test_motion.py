"""GraspService.PlanArmPath end to end: a KR 5 with the Barrett hand and a PA10 with the PG70 on the table plan
collision-free paths to a goal pose and to a goal configuration; numpy arrays back; the path's last waypoint puts
the tip on the goal (checked by the scene's own forward kinematics); blocked goals are FAILED_PRECONDITION with
the reason; bad input names the field."""
import grpc
import numpy as np
import pytest

import graspsim
from _support import expect_error

FP, IA, NF = grpc.StatusCode.FAILED_PRECONDITION, grpc.StatusCode.INVALID_ARGUMENT, grpc.StatusCode.NOT_FOUND
TABLE = 0.75
DOWN = [0, 1, 0, 0]  # w x y z: half a turn about x, the flange's +z pointing down


@pytest.fixture
def cell(client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0.1, 0.0, TABLE + 0.025, 1, 0, 0, 0])
    client.add_object(scene_id, "post", box=[0.06, 0.06, 0.4], pose=[0.0, 0.25, TABLE + 0.2, 1, 0, 0, 0],
                      mass=1.0, is_static=True)
    client.add_robot(scene_id, "kr5", builtin="kuka_kr5_sixx_r850_barrett", base_pose=[-0.45, 0, TABLE, 1, 0, 0, 0])
    return scene_id


def test_plan_to_a_pose_over_the_cube(client, cell):
    # The flange 36 cm above the cube's top: the Barrett's open fingers (26 cm) end 10 cm above it.
    goal = [0.1, 0.0, TABLE + 0.05 + 0.36] + DOWN
    path = client.plan_arm_path(cell, "kr5", goal=goal, seed=3)
    assert isinstance(path, graspsim.ArmPath)
    assert path.joint_ids == [f"kr5/joint_a{i}" for i in range(1, 7)]
    assert path.waypoints.shape[1] == 6 and path.waypoints.shape[0] >= 2
    assert path.times.shape == (path.waypoints.shape[0],) and path.times[0] == 0
    assert np.all(np.diff(path.times) >= 0) and path.duration == pytest.approx(path.times[-1])
    np.testing.assert_allclose(path.waypoints[0], np.zeros(6), atol=0)  # the scene's configuration
    assert path.tip_body == "kr5/flange" and path.checks > 0
    # The scene's own FK at the last waypoint puts the flange on the goal.
    client.set_joint_positions(cell, dict(zip(path.joint_ids, path.waypoints[-1])))
    flange = client.get_body_poses(cell, ["kr5/flange"])["kr5/flange"]
    np.testing.assert_allclose(flange.position, goal[:3], atol=1e-9)
    assert abs(abs(np.dot(flange.orientation, DOWN)) - 1) < 1e-9


def test_plan_to_a_configuration_and_back(client, cell):
    goal = [-0.5, 0.3, 0.2, 0.0, 0.8, 0.0]  # turned away from the post
    there = client.plan_arm_path(cell, "kr5", goal_positions=goal)
    np.testing.assert_allclose(there.waypoints[-1], goal, atol=0)
    back = client.plan_arm_path(cell, "kr5", start_positions=goal, goal_positions=[0] * 6)
    np.testing.assert_allclose(back.waypoints[0], goal, atol=0)
    np.testing.assert_allclose(back.waypoints[-1], np.zeros(6), atol=0)


def test_pa10_with_the_pg70(client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_robot(scene_id, "pa10", builtin="mitsubishi_pa10_pg70", base_pose=[-0.45, 0, TABLE, 1, 0, 0, 0])
    goal = [0.1, -0.1, TABLE + 0.30] + DOWN
    path = client.plan_arm_path(scene_id, "pa10", goal=goal)
    assert path.waypoints.shape[1] == 7
    client.set_joint_positions(scene_id, dict(zip(path.joint_ids, path.waypoints[-1])))
    flange = client.get_body_poses(scene_id, ["pa10/flange"])["pa10/flange"]
    np.testing.assert_allclose(flange.position, goal[:3], atol=1e-9)


def test_blocked_and_unreachable_goals_say_why(client, cell):
    with expect_error(FP, "goal pose unreachable: all ", "IK solutions collide", "touches table"):
        client.plan_arm_path(cell, "kr5", goal=[0.1, -0.2, TABLE - 0.05] + DOWN)  # inside the table
    with expect_error(FP, "goal pose unreachable: target out of reach"):
        client.plan_arm_path(cell, "kr5", goal=[1.5, 0, 1.0] + DOWN)
    with expect_error(FP, "goal unreachable: the goal configuration is blocked: kr5/"):
        client.plan_arm_path(cell, "kr5", goal_positions=[0, 2.2, 0, 0, 0, 0])  # the upper arm in the table


def test_bad_input_names_the_field(client, cell):
    with expect_error(NF, "arm_id: robot 'ur5' is not in the scene"):
        client.plan_arm_path(cell, "ur5", goal_positions=[0] * 6)
    with expect_error(IA, "goal_positions: 5 values for the 6 joints of arm 'kr5'"):
        client.plan_arm_path(cell, "kr5", goal_positions=[0] * 5)
    with expect_error(IA, "goal: absent"):
        client.plan_arm_path(cell, "kr5")
    with expect_error(IA, "goal, goal_positions: both given"):
        client.plan_arm_path(cell, "kr5", goal=[0.3, 0, 1.2] + DOWN, goal_positions=[0] * 6)
    with expect_error(IA, "timeout: 100 s is outside [0, 60]"):
        client.plan_arm_path(cell, "kr5", goal_positions=[0] * 6, timeout=100)
    with expect_error(IA, "start_positions[2]: nan is not finite"):
        client.plan_arm_path(cell, "kr5", goal_positions=[0] * 6, start_positions=[0, 0, float("nan"), 0, 0, 0])
    with expect_error(NF, "tip_body: 'kr5/nose' is not a body of robot 'kr5'"):
        client.plan_arm_path(cell, "kr5", goal_positions=[0] * 6, tip_body="kr5/nose")
