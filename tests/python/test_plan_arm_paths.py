"""GraspService.PlanArmPaths end to end: many PlanArmPath problems in one call, answered in order, each with its
path or its own error (a bad arm is NOT_FOUND, a blocked goal FAILED_PRECONDITION) without failing the others;
the planner is chosen per problem ("ompl_rrt_connect" reports itself, "bogus" is INVALID_ARGUMENT naming the
field); a batch answers exactly what single PlanArmPath calls with the same seeds answer; and with tokens on, a
problem naming a scene the caller may not read makes the call PERMISSION_DENIED (the interceptor reads the scene
ids of repeated fields)."""
import grpc
import numpy as np
import pytest

import graspsim
from _support import expect_error
from test_security import DENIED, connect as secure_connect, secure  # noqa: F401  (secure: the TLS + token server)

FP, IA, NF = grpc.StatusCode.FAILED_PRECONDITION, grpc.StatusCode.INVALID_ARGUMENT, grpc.StatusCode.NOT_FOUND
TABLE = 0.75
AWAY = [-0.5, 0.3, 0.2, 0.0, 0.8, 0.0]      # the KR 5 turned away from the post (free)
BLOCKED = [0, 2.2, 0, 0, 0, 0]              # the upper arm down through the table
ACROSS = [0.9, 0.4, 0.3, 0.0, 0.9, 0.0]     # across the post from AWAY: no straight line, the search runs


def kr5_cell(client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "post", box=[0.06, 0.06, 0.4], pose=[0.0, 0.25, TABLE + 0.2, 1, 0, 0, 0],
                      mass=1.0, is_static=True)
    client.add_robot(scene_id, "kr5", builtin="kuka_kr5_sixx_r850_barrett", base_pose=[-0.45, 0, TABLE, 1, 0, 0, 0])
    return scene_id


@pytest.fixture
def cell(client, scene_id):
    return kr5_cell(client, scene_id)


@pytest.fixture
def pa10_scene(client, request):
    sid = client.create_scene(f"{request.node.name[:100]}-pa10").id
    client.add_object(sid, "table", builtin="table")
    client.add_robot(sid, "pa10", builtin="mitsubishi_pa10_pg70", base_pose=[-0.45, 0, TABLE, 1, 0, 0, 0])
    yield sid
    client.delete_scene(sid)


def same_path(a: graspsim.ArmPath, b: graspsim.ArmPath):
    assert a.joint_ids == b.joint_ids and a.tip_body == b.tip_body and a.planner == b.planner
    np.testing.assert_array_equal(a.waypoints, b.waypoints)
    np.testing.assert_array_equal(a.times, b.times)
    assert (a.direct, a.checks, a.duration) == (b.direct, b.checks, b.duration)


def test_one_result_per_problem_in_order_errors_in_place(client, cell, pa10_scene):
    problems = [
        dict(scene_id=cell, arm_id="kr5", goal_positions=AWAY),
        dict(scene_id=cell, arm_id="ur5", goal_positions=AWAY),                 # no such arm
        dict(scene_id=cell, arm_id="kr5", goal_positions=BLOCKED),
        dict(scene_id=pa10_scene, arm_id="pa10", goal=[0.1, -0.1, TABLE + 0.30, 0, 1, 0, 0]),
        dict(scene_id=cell, arm_id="kr5", start_positions=AWAY, goal_positions=[0] * 6, seed=5),
    ]
    results = client.plan_arm_paths(problems)
    assert len(results) == len(problems)
    assert isinstance(results[0], graspsim.ArmPath)
    np.testing.assert_array_equal(results[0].waypoints[0], np.zeros(6))   # the scene's configuration
    np.testing.assert_array_equal(results[0].waypoints[-1], AWAY)
    assert isinstance(results[1], graspsim.GraspsimError)
    assert results[1].code == NF and "arm_id: robot 'ur5' is not in the scene" in results[1].message
    assert isinstance(results[2], graspsim.GraspsimError)
    assert results[2].code == FP
    assert "goal unreachable: the goal configuration is blocked: kr5/" in results[2].message
    assert "touches" in results[2].message
    assert isinstance(results[3], graspsim.ArmPath) and results[3].waypoints.shape[1] == 7
    assert results[3].joint_ids[0].startswith("pa10/") and results[3].tip_body == "pa10/flange"
    assert isinstance(results[4], graspsim.ArmPath)
    np.testing.assert_array_equal(results[4].waypoints[0], AWAY)
    np.testing.assert_array_equal(results[4].waypoints[-1], np.zeros(6))
    for r in (results[0], results[3], results[4]):
        assert r.planner == "rrt_connect" and r.checks > 0 and r.setup_seconds >= 0
        assert r.times.shape == (r.waypoints.shape[0],) and r.times[0] == 0 and np.all(np.diff(r.times) >= 0)
    # The single call answers the blocked goal with the same code and words.
    with expect_error(FP, results[2].message):
        client.plan_arm_path(cell, "kr5", goal_positions=BLOCKED)


def test_planner_per_problem(client, cell):
    results = client.plan_arm_paths([
        dict(scene_id=cell, arm_id="kr5", start_positions=AWAY, goal_positions=ACROSS, planner="ompl_rrt_connect"),
        dict(scene_id=cell, arm_id="kr5", goal_positions=AWAY, planner="bogus"),
        dict(scene_id=cell, arm_id="kr5", start_positions=AWAY, goal_positions=ACROSS, planner="rrt_connect"),
        dict(scene_id=cell, arm_id="kr5", start_positions=AWAY, goal_positions=ACROSS),
    ])
    assert [type(r) for r in results] == [graspsim.ArmPath, graspsim.InvalidArgument, graspsim.ArmPath,
                                          graspsim.ArmPath]
    assert results[0].planner == "ompl_rrt_connect"
    assert results[1].code == IA and "planner: 'bogus'" in results[1].message
    assert results[2].planner == results[3].planner == "rrt_connect"
    for r in (results[0], results[2]):
        np.testing.assert_array_equal(r.waypoints[0], AWAY)
        np.testing.assert_array_equal(r.waypoints[-1], ACROSS)
    same_path(results[2], results[3])  # "" is graspsim's own
    single = client.plan_arm_path(cell, "kr5", start_positions=AWAY, goal_positions=ACROSS, planner="ompl_rrt_connect")
    assert single.planner == "ompl_rrt_connect"
    with expect_error(IA, "planner: 'bogus'"):
        client.plan_arm_path(cell, "kr5", goal_positions=AWAY, planner="bogus")


@pytest.mark.parametrize("planner", ["rrt_connect", "ompl_rrt_connect"])
def test_batch_answers_what_single_calls_answer(client, cell, planner):
    problems = [dict(scene_id=cell, arm_id="kr5", start_positions=AWAY, goal_positions=ACROSS, seed=seed,
                     planner=planner) for seed in (1, 2, 3)]
    problems.append(dict(scene_id=cell, arm_id="kr5", goal=[0.1, 0.0, TABLE + 0.41, 0, 1, 0, 0], seed=4,
                         planner=planner))
    batch = client.plan_arm_paths(problems)
    assert all(isinstance(r, graspsim.ArmPath) for r in batch), batch
    assert not all(r.direct for r in batch), "every problem was a straight line: the seed would not matter"
    for problem, from_batch in zip(problems, batch):
        single = client.plan_arm_path(**problem)
        same_path(from_batch, single)
    # Different seeds searched differently (the seed reaches the search in the batch too).
    searched = [r for r in batch[:3] if not r.direct]
    assert len({r.checks for r in searched}) > 1 or len(searched) <= 1


def test_empty_batch_and_client_side_checks(client, cell):
    assert client.plan_arm_paths([]) == []
    with pytest.raises(TypeError, match="problems\\[0\\]: unknown keys \\['goal_position'\\]"):
        client.plan_arm_paths([dict(scene_id=cell, arm_id="kr5", goal_position=AWAY)])


def test_more_than_ten_thousand_problems_are_refused(client, cell):
    problem = dict(scene_id=cell, arm_id="kr5", goal_positions=AWAY)
    with expect_error(IA, "problems: 10001 problems; at most 10000 per call"):
        client.plan_arm_paths([problem] * 10001)


def test_a_problem_in_a_scene_the_caller_may_not_read_is_denied(secure):  # noqa: F811
    with secure_connect(secure, "alice") as alice, secure_connect(secure, "bob") as bob, \
            secure_connect(secure, "vera") as vera:
        alices = kr5_cell(alice, alice.create_scene("alice's cell").id)
        bobs = kr5_cell(bob, bob.create_scene("bob's cell").id)
        mine = dict(scene_id=bobs, arm_id="kr5", goal_positions=AWAY)
        theirs = dict(scene_id=alices, arm_id="kr5", goal_positions=AWAY)
        assert isinstance(bob.plan_arm_paths([mine])[0], graspsim.ArmPath)
        # A foreign scene anywhere in the batch refuses the whole call, before any planning.
        for batch in ([theirs], [mine, theirs], [mine, mine, theirs, mine]):
            with expect_error(DENIED, "is not yours"):
                bob.plan_arm_paths(batch)
        with expect_error(DENIED, "is not yours"):
            bob.plan_arm_path(alices, "kr5", goal_positions=AWAY)
        # A viewer may not plan at all.
        with expect_error(DENIED, "needs role scripter"):
            vera.plan_arm_paths([theirs])
        # Shared for reading: planning in it is allowed (it does not change the scene).
        alice.share_scene(alices, "bob")
        results = bob.plan_arm_paths([mine, theirs])
        assert [type(r) for r in results] == [graspsim.ArmPath, graspsim.ArmPath]
        alice.delete_scene(alices)
        bob.delete_scene(bobs)
