"""Objects: primitives, meshes and built-ins as the server holds them."""
import numpy as np
import pytest

import graspsim
from graspsim import inertia, meshes

TILTED = graspsim.Pose([0.1, -0.2, 0.8], graspsim.quaternion_about_axis([1, 2, 3], 0.7))


def body_by_id(client, scene_id, body_id, include_geometry=False) -> graspsim.Body:
    bodies = {b.id: b for b in client.get_scene(scene_id, include_geometry=include_geometry).bodies}
    return bodies[body_id]


@pytest.mark.parametrize("shape, expected", [
    (dict(box=(0.1, 0.2, 0.3)), inertia.box_inertia(2.0, (0.1, 0.2, 0.3))),
    (dict(sphere=0.05), inertia.sphere_inertia(2.0, 0.05)),
    (dict(cylinder=(0.03, 0.12)), inertia.cylinder_inertia(2.0, 0.03, 0.12)),
])
def test_primitive_with_computed_inertia(client, scene_id, shape, expected):
    added = client.add_object(scene_id, "thing", mass=2.0, pose=TILTED, **shape)
    held = body_by_id(client, scene_id, "thing")
    for body in (added, held):
        assert body.id == "thing" and body.robot_id == "" and body.motion == "free"
        assert body.inertial.mass == 2.0 and body.triangle_count == 0
        np.testing.assert_allclose(body.inertial.inertia, expected, rtol=1e-12)
        np.testing.assert_allclose(body.pose.as_array(), TILTED.as_array(), atol=1e-12)
        assert (body.material.static_friction, body.material.dynamic_friction) == (0.6, 0.4)
        assert len(body.collision) == 1 and body.collision[0].shape == next(iter(shape))


def test_static_box_with_friction(client, scene_id):
    client.add_object(scene_id, "wall", box=(1, 0.1, 1), mass=10.0, is_static=True, friction=(0.9, 0.7))
    body = body_by_id(client, scene_id, "wall")
    assert body.motion == "static"
    assert (body.material.static_friction, body.material.dynamic_friction) == (0.9, 0.7)


def test_mesh_object_and_geometry_bytes(client, scene_id):
    vertices, triangles = meshes.uv_sphere(0.04, 8, 12)
    vertices = vertices + [0.01, 0.0, 0.0]
    added = client.add_object(scene_id, "ball", mesh=(vertices, triangles), mass=0.3, pose=[0, 0, 1, 1, 0, 0, 0])
    assert added.triangle_count == len(triangles) and added.motion == "free"
    com, expected = inertia.mesh_inertia(0.3, vertices, triangles)
    held = body_by_id(client, scene_id, "ball")
    np.testing.assert_allclose(held.inertial.inertia, expected, rtol=1e-12)
    np.testing.assert_allclose(held.inertial.center_of_mass, com, atol=1e-12)
    assert held.triangle_count == len(triangles)
    geometry = body_by_id(client, scene_id, "ball", include_geometry=True).collision[0]
    assert geometry.shape == "mesh"
    # The very values sent: float32 vertices (the wire's), uint32 triangles.
    np.testing.assert_array_equal(geometry.vertices, vertices.astype(np.float32))
    np.testing.assert_array_equal(geometry.triangles, triangles)
    assert body_by_id(client, scene_id, "ball").collision[0].vertices.size == 0


def test_builtins_table_and_cube(client, scene_id):
    models = {m.name: m for m in client.builtin_models()}
    assert models["table"].kind == "object" and models["cube_5cm"].kind == "object"
    assert models["schunk_pg70"].kind == "robot"
    assert all(m.description for m in models.values())
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, 0.775, 1, 0, 0, 0])
    scene = client.get_scene(scene_id)
    bodies = {b.id: b for b in scene.bodies}
    assert bodies["table"].motion == "static"
    assert bodies["cube"].motion == "free" and bodies["cube"].inertial.mass == pytest.approx(0.1)
    np.testing.assert_allclose(bodies["cube"].pose.position, [0, 0, 0.775])
    assert scene.summary.body_count == 2


def test_builtin_with_own_mass_and_inertia(client, scene_id):
    body = client.add_object(scene_id, "heavy", builtin="cube_5cm", mass=0.5,
                             inertia=inertia.box_inertia(0.5, [0.05] * 3))
    assert body.inertial.mass == 0.5 and body.motion == "free"


def test_remove_object(client, scene_id):
    client.add_object(scene_id, "a", sphere=0.02, mass=0.1)
    client.add_object(scene_id, "b", sphere=0.02, mass=0.1)
    assert client.remove_body(scene_id, "a") == ["a"]
    assert [b.id for b in client.get_scene(scene_id).bodies] == ["b"]
