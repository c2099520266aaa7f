"""Scenes: create, list, get, delete; unknown ids; the scene limit."""
import grpc
import pytest

import graspsim

NOT_FOUND = grpc.StatusCode.NOT_FOUND
MISSING = "no-such-scene"


def test_create_list_get_delete(client):
    summary = client.create_scene("lifecycle")
    assert summary.id and summary.name == "lifecycle"
    assert summary.body_count == 0 and summary.robot_count == 0
    assert summary.id in {s.id for s in client.list_scenes()}
    scene = client.get_scene(summary.id)
    assert scene.summary.id == summary.id and scene.summary.name == "lifecycle"
    assert len(scene.bodies) == len(scene.joints) == len(scene.robots) == 0
    other = client.create_scene("lifecycle")
    assert other.id != summary.id, "scene names are not unique, ids are"
    client.delete_scene(summary.id)
    client.delete_scene(other.id)
    ids = {s.id for s in client.list_scenes()}
    assert summary.id not in ids and other.id not in ids
    with pytest.raises(graspsim.GraspsimError) as info:
        client.get_scene(summary.id)
    assert info.value.code == NOT_FOUND


def test_revision_increases_with_changes(client, scene_id):
    first = client.get_scene(scene_id).summary.revision
    client.add_object(scene_id, "box", box=(0.1, 0.1, 0.1), mass=1.0)
    scene = client.get_scene(scene_id)
    assert scene.summary.revision > first
    assert scene.summary.body_count == 1


# Every method that takes a scene id, called with one that does not exist.
UNKNOWN_SCENE_CALLS = {
    "get_scene": lambda c: c.get_scene(MISSING),
    "delete_scene": lambda c: c.delete_scene(MISSING),
    "upload_file": lambda c: c.upload_file(MISSING, "a.stl", b"solid"),
    "add_object": lambda c: c.add_object(MISSING, "box", box=(0.1, 0.1, 0.1), mass=1.0),
    "add_robot": lambda c: c.add_robot(MISSING, "pg70", builtin="schunk_pg70"),
    "remove_body": lambda c: c.remove_body(MISSING, "box"),
    "set_body_poses": lambda c: c.set_body_pose(MISSING, "box", [0, 0, 0, 1, 0, 0, 0]),
    "get_body_poses": lambda c: c.get_body_poses(MISSING),
    "set_joint_positions": lambda c: c.set_joint_positions(MISSING, {"pg70/finger_left_joint": 0.01}),
    "get_joint_positions": lambda c: c.get_joint_positions(MISSING),
    "watch_scene": lambda c: next(c.watch_scene(MISSING)),
    "step_simulation": lambda c: c.step_simulation(MISSING, steps=1),
    "set_simulation_params": lambda c: c.set_simulation_params(MISSING, time_step=1e-3),
    "get_simulation_params": lambda c: c.get_simulation_params(MISSING),
    "set_actuator": lambda c: c.set_actuator(MISSING, "pg70/finger_left_joint", "velocity", 0.01),
}


@pytest.mark.parametrize("method", sorted(UNKNOWN_SCENE_CALLS))
def test_unknown_scene_is_not_found(client, method):
    with pytest.raises(graspsim.GraspsimError) as info:
        UNKNOWN_SCENE_CALLS[method](client)
    assert info.value.code == NOT_FOUND, str(info.value)
    assert MISSING in info.value.message, str(info.value)


def test_max_scenes(start_server):
    server = start_server("--max-scenes=3")
    with graspsim.connect(server.address) as c:
        ids = [c.create_scene(f"s{i}").id for i in range(3)]
        with pytest.raises(graspsim.GraspsimError) as info:
            c.create_scene("one too many")
        assert info.value.code == grpc.StatusCode.RESOURCE_EXHAUSTED, str(info.value)
        assert "3" in info.value.message, str(info.value)
        assert sorted(s.id for s in c.list_scenes()) == sorted(ids)
        c.delete_scene(ids[0])
        assert c.create_scene("fits again").id


def test_too_long_scene_name_is_invalid(client):
    before = {s.id for s in client.list_scenes()}
    with pytest.raises(graspsim.GraspsimError) as info:
        client.create_scene("x" * 129)
    assert info.value.code == grpc.StatusCode.INVALID_ARGUMENT, str(info.value)
    assert "name" in info.value.message, str(info.value)
    assert {s.id for s in client.list_scenes()} == before


def test_readme_example_passes_the_created_scene_itself(client):
    """README's first example hands create_scene's SceneSummary on as the scene: every method taking a scene takes
    the object carrying its id (a Scene from get_scene too); anything else is a TypeError naming the parameter."""
    scene = client.create_scene("readme")
    client.add_object(scene, "table", builtin="table")
    client.add_object(scene, "cube", builtin="cube_5cm", pose=[0, 0, 0.775, 1, 0, 0, 0])
    client.add_robot(scene, "pg70", builtin="schunk_pg70", base_pose=[0, 0, 0.91, 0, 1, 0, 0])
    client.set_joint_positions(scene, {"pg70/finger_left_joint": 0.03})
    assert set(client.get_body_poses(scene)) >= {"table", "cube", "pg70/base_link"}
    full = client.get_scene(scene)
    assert client.step_simulation(full, duration=0.01).steps == 10
    assert client.get_body_poses(scene.id).keys() == client.get_body_poses(full).keys()
    with pytest.raises(TypeError, match="scene_id: a scene id"):
        client.get_body_poses(42)
    with pytest.raises(TypeError, match="add_to_scene_id: a scene id"):
        client.complete_shape([0, 0, 1, 1, 0, 0, 0], points=[[0, 0, 0]] * 3, add_to_scene_id=3.5)
    client.delete_scene(scene)


def test_errors_are_subclasses_of_their_status_and_still_graspsim_errors(client):
    with pytest.raises(graspsim.NotFound) as not_found:
        client.get_scene("scene-does-not-exist")
    assert isinstance(not_found.value, graspsim.GraspsimError) and not_found.value.code == grpc.StatusCode.NOT_FOUND
    assert "scene_id" in not_found.value.message
    scene = client.create_scene("errors")
    client.add_object(scene, "cube", builtin="cube_5cm")
    with pytest.raises(graspsim.AlreadyExists):
        client.add_object(scene, "cube", builtin="cube_5cm")
    with pytest.raises(graspsim.InvalidArgument, match="INVALID_ARGUMENT"):
        client.set_body_poses(scene, {"cube": [0, 0, 0, 2, 0, 0, 0]})  # not a unit quaternion
    client.delete_scene(scene)
