"""The dynamic simulation through the real server: stepping, parameters, actuators, divergence, visibility.

The engine's accuracy against analytic answers is tested in C++ (tests/cpp/physics); here the RPCs around it.
"""
import json
import urllib.request

import grpc
import numpy as np
import pytest

import graspsim
from graspsim.v1 import scene_pb2

from _support import expect_error

TABLE_TOP = 0.75          # m, built-in table
CUBE = 0.05               # m, built-in cube_5cm edge
DOWN = graspsim.quaternion_about_axis([1, 0, 0], np.pi)  # gripper approach (its +z) along world -z
LEFT = "pg70/finger_left_joint"


def body(client, scene_id, body_id):
    return next(b for b in client.get_scene(scene_id).bodies if b.id == body_id)


@pytest.fixture
def table_and_cube(client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2 + 0.01, 1, 0, 0, 0])
    return scene_id


def test_dropped_cube_settles_on_the_table_and_falls_asleep(client, table_and_cube):
    response = client.step_simulation(table_and_cube, duration=1.5)
    assert response.steps == 1500 and response.time == pytest.approx(1.5, abs=1e-9)
    cube = body(client, table_and_cube, "cube")
    # Resting on soft contacts: below the table top by the penetration m g / (n k), far under 1 mm.
    assert TABLE_TOP + CUBE / 2 - 1e-3 < cube.pose.position[2] < TABLE_TOP + CUBE / 2
    assert np.linalg.norm(cube.velocity.linear) < 1e-3
    assert cube.sleeping and response.awake_bodies == 0
    # Asleep: further steps skip it and move nothing.
    before = cube.pose.position[2]
    assert client.step_simulation(table_and_cube, steps=100).contacts == 0
    assert body(client, table_and_cube, "cube").pose.position[2] == before


def test_free_fall_through_the_api_matches_the_closed_form(client, scene_id):
    client.set_simulation_params(scene_id, integrator="velocity_verlet")
    client.add_object(scene_id, "ball", sphere=0.02, mass=0.1, pose=[0, 0, 10, 1, 0, 0, 0])
    client.step_simulation(scene_id, steps=500)
    ball = body(client, scene_id, "ball")
    assert 10 - ball.pose.position[2] == pytest.approx(0.5 * 9.81 * 0.5 ** 2, rel=1e-6)
    assert ball.velocity.linear[2] == pytest.approx(-9.81 * 0.5, rel=1e-9)


def test_steps_duration_and_until_time(client, scene_id):
    client.set_simulation_params(scene_id, time_step=2e-3)
    assert client.step_simulation(scene_id, steps=10).time == pytest.approx(0.02)
    assert client.step_simulation(scene_id, duration=0.1).steps == 50
    response = client.step_simulation(scene_id, until_time=0.5)
    assert response.steps == 190 and response.time == pytest.approx(0.5)
    assert client.get_scene(scene_id).summary.time == pytest.approx(0.5)
    with expect_error(grpc.StatusCode.INVALID_ARGUMENT, "until_time", "0.1", "before"):
        client.step_simulation(scene_id, until_time=0.1)
    with expect_error(grpc.StatusCode.INVALID_ARGUMENT, "duration"):
        client.step_simulation(scene_id, duration=-1.0)
    with pytest.raises(grpc.RpcError) as info:  # the raw stub: the client itself insists on one amount
        client.scene_stub.StepSimulation(scene_pb2.StepSimulationRequest(scene_id=scene_id), timeout=10)
    assert info.value.code() == grpc.StatusCode.INVALID_ARGUMENT and "amount" in info.value.details()
    assert client.get_scene(scene_id).summary.time == pytest.approx(0.5), "refused requests change nothing"


def test_simulation_params_round_trip_and_bad_values_change_nothing(client, scene_id):
    defaults = client.get_simulation_params(scene_id)
    assert defaults.time_step == pytest.approx(1e-3) and defaults.substeps == 1
    assert defaults.integrator == "linearly_implicit_euler" and defaults.engine == "graspsim"
    assert defaults.gravity[2] == pytest.approx(-9.81) and defaults.contact.stiffness > 0
    params = client.set_simulation_params(scene_id, time_step=5e-4, substeps=2, integrator="semi_implicit_euler",
                                          gravity=[0, 0, -1.62], contact={"stiffness": 2e4, "stribeck_velocity": 0.02})
    again = client.get_simulation_params(scene_id)
    assert again == params and again.integrator == "semi_implicit_euler"
    assert (again.time_step, again.substeps, again.gravity[2]) == pytest.approx((5e-4, 2, -1.62))
    assert again.contact.stiffness == pytest.approx(2e4) and again.contact.stribeck_velocity == pytest.approx(0.02)
    assert again.contact.damping == pytest.approx(defaults.contact.damping), "unset fields keep the defaults"
    for bad, field in [(dict(time_step=-1.0), "params.time_step"), (dict(substeps=5000), "params.substeps"),
                       (dict(contact={"stiffness": float("nan")}), "params.contact.stiffness"),
                       (dict(sample_spacing=1e-6), "params.sample_spacing")]:
        with expect_error(grpc.StatusCode.INVALID_ARGUMENT, field):
            client.set_simulation_params(scene_id, **bad)
    assert client.get_simulation_params(scene_id) == params


def test_pg70_closes_on_the_cube_and_holds_it_when_the_table_goes(client, table_and_cube):
    scene_id = table_and_cube
    base_z = TABLE_TOP + CUBE / 2 + 0.145  # fingertips 12 mm above the table, the housing clear of the cube
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70", base_pose=graspsim.Pose([0, 0, base_z], DOWN))
    client.set_joint_positions(scene_id, {LEFT: 0.03})
    client.step_simulation(scene_id, duration=0.3)  # the cube drops its 1 cm and rests
    client.set_actuator(scene_id, LEFT, "velocity", -0.05, current_limit=2.0)
    client.step_simulation(scene_id, duration=0.8)
    joints = {j.id: j for j in client.get_scene(scene_id).joints}
    # Closed on the 5 cm cube: the pads' foam (4 mm, its surface at q + 1 mm from the centre) meets the cube's
    # faces at q = 24 mm and is compressed by the grip, 114 N on 84 elements of 1e3 N/m: about 1.4 mm.
    assert 0.0215 < joints[LEFT].position < 0.024
    assert abs(joints[LEFT].velocity) < 1e-3, "stalled against the cube at the current limit"
    z_before = body(client, scene_id, "cube").pose.position[2]
    client.remove_body(scene_id, "table")
    response = client.step_simulation(scene_id, duration=0.5)
    cube = body(client, scene_id, "cube")
    assert response.contacts > 0
    assert abs(cube.pose.position[2] - z_before) < 1e-4, "held by friction, not dropped"


def test_actuator_errors_name_the_joint_and_change_nothing(client, scene_id):
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70")
    with expect_error(grpc.StatusCode.NOT_FOUND, "commands[0].joint_id", "pg70/nope"):
        client.set_actuator(scene_id, "pg70/nope", "velocity", 0.01)
    with expect_error(grpc.StatusCode.INVALID_ARGUMENT, "pg70/finger_right_joint", "mimic"):
        client.set_actuator(scene_id, "pg70/finger_right_joint", "velocity", 0.01)
    with expect_error(grpc.StatusCode.INVALID_ARGUMENT, "commands[0].value"):
        client.set_actuator(scene_id, LEFT, "position", float("inf"))
    client.step_simulation(scene_id, steps=50)
    assert client.get_joint_positions(scene_id)[LEFT] == 0.0, "no drive was installed"


def test_position_mode_reaches_the_target(client, scene_id):
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70")
    client.set_actuator(scene_id, LEFT, "position", 0.02)
    client.step_simulation(scene_id, duration=1.0)
    positions = client.get_joint_positions(scene_id)
    assert positions[LEFT] == pytest.approx(0.02, abs=1e-4)
    assert positions["pg70/finger_right_joint"] == positions[LEFT], "the mimic finger follows"


def test_divergence_is_reported_and_the_scene_keeps_its_last_finite_state(client, scene_id):
    client.set_simulation_params(scene_id, integrator="semi_implicit_euler", time_step=1e-2,
                                 contact={"stiffness": 1e8, "damping": 1e-9})
    client.add_object(scene_id, "floor", box=[1, 1, 0.1], mass=100, pose=[0, 0, -0.05, 1, 0, 0, 0],
                      is_static=True)
    client.add_object(scene_id, "fingertip", sphere=0.01, mass=0.05, pose=[0, 0, 0.009, 1, 0, 0, 0])
    with expect_error(grpc.StatusCode.FAILED_PRECONDITION, "fingertip", "step", "velocity"):
        client.step_simulation(scene_id, steps=1000)
    tip = body(client, scene_id, "fingertip")
    assert np.isfinite(tip.pose.position).all()
    assert client.get_scene(scene_id).summary.time < 10.0


def test_watchers_see_the_motion(client, scene_id):
    client.add_object(scene_id, "ball", sphere=0.02, mass=0.1, pose=[0, 0, 1, 1, 0, 0, 0])
    with client.watch_scene(scene_id) as watch:
        first = next(watch)
        client.step_simulation(scene_id, duration=0.2)
        snapshot = next(watch)
        while snapshot.time < 0.2 - 1e-9:
            snapshot = next(watch)
    assert first.time == 0 and snapshot.time == pytest.approx(0.2)
    assert snapshot.poses[0][2] == pytest.approx(1 - 0.5 * 9.81 * 0.2 ** 2, abs=2e-3)


def test_stepping_over_http_json(client, server, scene_id):
    request = urllib.request.Request(f"{server.http_url}/v1/SceneService/StepSimulation",
                                     data=json.dumps({"scene_id": scene_id, "steps": 25}).encode(),
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=10) as response:
        reply = json.load(response)
    assert reply["time"] == pytest.approx(0.025) and int(reply["steps"]) == 25
