"""Body and joint velocities through the API (GetBodyPoses/SetBodyPoses' velocity, JointPosition.velocity): set,
read back, and followed by the closed-form motion; bad values refused naming the field, nothing changed."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import graspsim

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "physics"))
from textbook import PENDULUM  # noqa: E402

G = 9.81


def test_a_thrown_ball_follows_the_parabola(client, scene_id):
    client.set_simulation_params(scene_id, integrator="velocity_verlet")  # exact under a constant force
    client.add_object(scene_id, "ball", sphere=0.05, mass=1.0, pose=[0, 0, 10, 1, 0, 0, 0])
    client.set_body_velocities(scene_id, {"ball": [1.0, -2.0, 5.0, 0, 0, 0]})
    velocity = client.get_body_velocities(scene_id)["ball"]
    np.testing.assert_allclose(velocity.linear, [1, -2, 5])
    client.step_simulation(scene_id, steps=500)  # 0.5 s
    t = 0.5
    np.testing.assert_allclose(client.get_body_poses(scene_id, ["ball"])["ball"].position,
                               [t, -2 * t, 10 + 5 * t - G * t * t / 2], atol=1e-9)
    np.testing.assert_allclose(client.get_body_velocities(scene_id, ["ball"])["ball"].linear,
                               [1, -2, 5 - G * t], atol=1e-9)


def test_a_spinning_sphere_turns_at_its_rate(client, scene_id):
    client.set_simulation_params(scene_id, gravity=(0, 0, 0))
    client.add_object(scene_id, "ball", sphere=0.05, mass=1.0)
    client.set_body_velocities(scene_id, {"ball": graspsim.Velocity([0, 0, 0], [0, 0, 2.0])})
    client.step_simulation(scene_id, steps=500)  # 0.5 s: 1 rad about z
    q = client.get_body_poses(scene_id, ["ball"])["ball"].orientation
    np.testing.assert_allclose(q, [math.cos(0.5), 0, 0, math.sin(0.5)], atol=1e-9)
    np.testing.assert_allclose(client.get_body_velocities(scene_id, ["ball"])["ball"].angular, [0, 0, 2], atol=1e-12)


def test_static_bodies_and_links_have_no_velocity_of_their_own(client, scene_id):
    client.add_object(scene_id, "wall", box=[1, 1, 1], is_static=True)
    client.add_object(scene_id, "ball", sphere=0.05, mass=1.0, pose=[0, 0, 2, 1, 0, 0, 0])
    client.add_robot(scene_id, "p", urdf=PENDULUM)
    assert set(client.get_body_velocities(scene_id)) == {"ball"}
    for body, word in (("wall", "static"), ("p/bob", "robot")):
        with pytest.raises(graspsim.FailedPrecondition, match=f"'{body}'.*{word}"):
            client.set_body_velocities(scene_id, {"ball": [1, 0, 0, 0, 0, 0], body: [1, 0, 0, 0, 0, 0]})
    with pytest.raises(graspsim.InvalidArgument, match=r"velocity\[ball\].linear"):
        client.set_body_velocities(scene_id, {"ball": [math.nan, 0, 0, 0, 0, 0]})
    np.testing.assert_array_equal(client.get_body_velocities(scene_id)["ball"].linear, [0, 0, 0])  # all or nothing
    with pytest.raises(ValueError, match="6 values"):
        client.set_body_velocities(scene_id, {"ball": [1, 2, 3]})


def test_joint_velocities_are_set_read_and_followed(client, scene_id):
    client.set_simulation_params(scene_id, gravity=(0, 0, 0))
    client.add_robot(scene_id, "p", urdf=PENDULUM)
    client.set_joint_positions(scene_id, {"p/hinge": 0.1}, velocities={"p/hinge": 0.5})
    assert client.get_joint_velocities(scene_id, ["p/hinge"]) == {"p/hinge": 0.5}
    client.step_simulation(scene_id, steps=1000)  # no force: uniform rotation for 1 s
    assert client.get_joint_positions(scene_id)["p/hinge"] == pytest.approx(0.6, abs=1e-9)
    with pytest.raises(graspsim.InvalidArgument, match=r"velocities\[p/hinge\]"):
        client.set_joint_positions(scene_id, {"p/hinge": 0.2}, velocities={"p/hinge": math.inf})
    assert client.get_joint_positions(scene_id)["p/hinge"] == pytest.approx(0.6, abs=1e-9)
    with pytest.raises(ValueError, match="no position"):
        client.set_joint_positions(scene_id, {}, velocities={"p/hinge": 1.0})
