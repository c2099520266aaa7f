"""GraspService.PickAndPlace end to end: a KR 5 with the PG70 moves a 5 cm cube across the table in the dynamic
simulation. Checked from the scene itself (GetBodyPoses), not from the server's verdict: the cube ends within
1 cm and 10° of the goal; the executed arm motions stay within the joint limits the scene reports. An unreachable
goal is FAILED_PRECONDITION naming why and leaves the scene unchanged; bad input names the field; cancelling
the stream ends the job without touching the scene."""
import grpc
import numpy as np
import pytest

import graspsim
from _support import assert_rejected, whole_scene

FP, IA, NF = grpc.StatusCode.FAILED_PRECONDITION, grpc.StatusCode.INVALID_ARGUMENT, grpc.StatusCode.NOT_FOUND
TABLE = 0.75
START = [0.05, 0.2, TABLE + 0.025, 1, 0, 0, 0]
GOAL = [0.05, -0.2, TABLE + 0.025, 1, 0, 0, 0]


@pytest.fixture
def cell(client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=START)
    client.add_robot(scene_id, "kr5", builtin="kuka_kr5_sixx_r850_pg70", base_pose=[-0.45, 0, TABLE, 1, 0, 0, 0])
    return scene_id


def angle_between(q1, q2) -> float:
    return 2 * np.arccos(min(1.0, abs(float(np.dot(q1, q2)))))


def test_the_cube_ends_at_the_goal(client, cell):
    stages = []
    result = client.pick_and_place(cell, "kr5", "cube", GOAL, hand_id="schunk_pg70",
                                   on_progress=lambda stage, fraction: stages.append((stage, fraction)))
    assert isinstance(result, graspsim.PickAndPlaceResult) and result.success
    names = [s for s, _ in stages]
    # Progress is newest-only (rpc/progress_run.h): a stage of a few milliseconds (filtering, planning a path) may
    # be replaced by the next before it is written; the simulated stages last long enough to be seen.
    known = {"planning_grasps", "filtering", "planning_path", "approach", "close", "lift", "transfer", "release",
             "retreat", "done"}
    for stage in ("approach", "close", "lift", "transfer", "release", "retreat", "done"):
        assert stage in names, names
    assert set(names) <= known and names[-1] == "done"
    fractions = [f for _, f in stages]
    assert all(0 <= f <= 1 for f in fractions) and fractions[-1] == 1
    # The scene's own body pose, against the goal: 1 cm, 10°.
    cube = client.get_body_poses(cell, ["cube"])["cube"]
    assert np.linalg.norm(np.asarray(cube.position) - GOAL[:3]) < 0.01
    assert angle_between(cube.orientation, GOAL[3:]) < np.radians(10)
    np.testing.assert_allclose(result.object_pose.position, cube.position, atol=1e-9)
    assert result.position_error < 0.01 and result.grip_force > 0 and result.reachable >= 1
    # Every executed motion within the joint limits the scene reports; times increasing from 0.
    limits = {j.id: (j.lower, j.upper) for j in client.get_scene(cell).joints}
    assert result.joint_ids == [f"kr5/joint_a{i}" for i in range(1, 7)]
    assert [m.stage for m in result.motions] == ["approach", "approach", "lift", "transfer", "transfer", "retreat"]
    for m in result.motions:
        assert m.waypoints.shape[1] == 6 and m.times.shape == (m.waypoints.shape[0],) and m.times[0] == 0
        assert np.all(np.diff(m.times) > 0)
        for k, joint in enumerate(result.joint_ids):
            lo, hi = limits[joint]
            assert np.all(m.waypoints[:, k] >= lo - 1e-9) and np.all(m.waypoints[:, k] <= hi + 1e-9)
    assert len(result.grasp_set_id) == 64  # the SHA-256 key of the stored set
    # The grasp that succeeded: a row of the set's structured array, its contacts beside it (object frame).
    assert result.grasp["outcome"] == "grasp" and result.grasp["force_closure"]
    assert len(result.grasp_contacts) == result.grasp["contact_count"] > 0


def test_an_unreachable_goal_is_named_and_changes_nothing(client, cell):
    far = [1.8, 0.0, TABLE + 0.025, 1, 0, 0, 0]  # 2.25 m from the base: the KR 5 reaches 0.85 m
    assert_rejected(client, cell, FP, ["is reachable", "unreachable: above the goal"],
                    lambda: client.pick_and_place(cell, "kr5", "cube", far))


@pytest.mark.parametrize("kwargs, code, parts", [
    (dict(arm_id="ghost"), NF, ["arm_id", "ghost"]),
    (dict(arm_id=""), IA, ["arm_id", "empty"]),
    (dict(body_id="ghost"), NF, ["body_id", "ghost"]),
    (dict(body_id="table"), IA, ["body_id", "'table' is not a free body"]),
    (dict(hand_id="barrett_bh8_282"), IA, ["hand_id", "barrett_bh8_282", "schunk_pg70"]),
    (dict(hand_id="claw"), IA, ["hand_id", "claw"]),
    (dict(goal=[float("nan"), 0, 0.8, 1, 0, 0, 0]), IA, ["goal"]),
    (dict(grasp_set_id="0" * 64), NF, ["grasp_set_id"]),
    (dict(max_attempts=1000), IA, ["max_attempts", "1000"]),
])
def test_bad_input_is_named(client, cell, kwargs, code, parts):
    args = dict(arm_id="kr5", body_id="cube", goal=GOAL)
    args.update(kwargs)
    assert_rejected(client, cell, code, parts, lambda: client.pick_and_place(
        cell, args.pop("arm_id"), args.pop("body_id"), args.pop("goal"), **args))


def test_not_an_arm(client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=START)
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70", base_pose=[0, 0, 1.2, 1, 0, 0, 0])
    assert_rejected(client, scene_id, IA, ["arm_id", "'pg70' is not an arm"],
                    lambda: client.pick_and_place(scene_id, "pg70", "cube", GOAL))


def test_an_unknown_scene_is_not_found(client):
    with pytest.raises(graspsim.GraspsimError) as info:
        client.pick_and_place("no-such-scene", "kr5", "cube", GOAL)
    assert info.value.code == NF


def test_cancel_stops_the_job_and_changes_nothing(client, cell):
    before = whole_scene(client, cell)
    stream = client.pick_and_place_stream(cell, "kr5", "cube", GOAL)
    seen = []
    for message in stream:
        seen.append(message.stage)
        if message.stage in ("approach", "close"):
            stream.cancel()
    assert "done" not in seen and seen, seen
    # The job stops at its next progress call; the scene never took a state from it.
    assert whole_scene(client, cell) == before
    # And the server is free for the next request at once.
    assert client.get_body_poses(cell, ["cube"])["cube"] is not None
