"""No generated protobuf message in the Python client's public API (issue 24): every reply is a dataclass or numpy
arrays, every parameter a dataclass or plain Python/numpy values, and a scene or body is named by its id or by the
object that carries it (SceneLike, BodyLike).

Checked two ways: statically, every public method's annotations (typing.get_type_hints) must name no Message class;
and against a real server, the replies of the calls that used to hand out messages must hold none, at any depth
(a field annotated `object` once held a Grasp message: only the values tell). The generated messages stay
reachable through the raw stubs and the dataclasses' from_proto/to_proto, the bridge to graspsim.v1."""
import dataclasses
import importlib
import inspect
import os
import subprocess
import sys
import typing
from pathlib import Path

import numpy as np
import pytest
from google.protobuf.message import Message

import graspsim
from graspsim import meshes
from graspsim.v1 import common_pb2, scene_pb2
from _support import cube_stl

CLIENT = Path(__file__).resolve().parents[2] / "clients" / "python"
# The modules a user imports, and the classes they export.
MODULES = ["graspsim", "graspsim.viewer", "graspsim.fleet", "graspsim.meshes", "graspsim.inertia", "graspsim.mcap",
           "graspsim.plot", "graspsim.batch", "graspsim.testing", "graspsim.testing.fleet",
           "graspsim.testing.gateway_rig", "graspsim.testing.partial_view"]
# The documented bridge to the generated messages, for code that uses the raw stubs or reads recordings.
BRIDGES = {"from_proto", "to_proto", "from_progress", "pack_mesh", "unpack_mesh"}


def messages_in(hint) -> list:
    """The Message classes a type hint names, through Union, Optional, generics and Callable."""
    if isinstance(hint, (list, tuple)):  # Callable's argument list
        return [m for h in hint for m in messages_in(h)]
    found = [hint] if isinstance(hint, type) and issubclass(hint, Message) else []
    return found + [m for arg in typing.get_args(hint) for m in messages_in(arg)]


def type_checking_names() -> dict:
    """The names the modules import under TYPE_CHECKING only, for get_type_hints; and os, which a type alias
    (PemLike, FilePath) names in a string that get_type_hints evaluates in the using module."""
    names = {"Client": graspsim.Client, "Device": graspsim.Device, "os": os}
    for module, name in (("matplotlib.axes", "Axes"), ("matplotlib.figure", "Figure"),
                         ("mpl_toolkits.mplot3d", "Axes3D"), ("tqdm", "tqdm"), ("graspsim.batch._pool", "PoolStats")):
        try:
            names[name] = getattr(importlib.import_module(module), name)
        except ImportError:
            names[name] = object  # the module's optional extra is not installed: nothing to find in it
    try:
        names["trimesh"] = importlib.import_module("trimesh")
    except ImportError:
        pass
    return names


def public_callables():
    """(where, function) of every public Client method and every public function or method of the modules users
    import (the bridges left out)."""
    yield from ((f"Client.{name}", member) for name, member in inspect.getmembers(graspsim.Client, inspect.isfunction)
                if not name.startswith("_"))
    for module_name in MODULES:
        try:
            module = importlib.import_module(module_name)
        except ImportError:  # an optional extra (ray, matplotlib, mcap) not installed
            continue
        for name in getattr(module, "__all__", [n for n in vars(module) if not n.startswith("_")]):
            member = getattr(module, name)
            if name in BRIDGES or getattr(member, "__module__", "").startswith("graspsim.v1"):
                continue
            if inspect.isfunction(member):
                yield f"{module_name}.{name}", member
            elif inspect.isclass(member) and member.__module__.startswith("graspsim") and member is not graspsim.Client:
                for method_name, method in inspect.getmembers(member, inspect.isfunction):
                    if not method_name.startswith("_") and method_name not in BRIDGES:
                        yield f"{module_name}.{name}.{method_name}", method
                for method_name, method in inspect.getmembers(member, inspect.ismethod):  # classmethods
                    if not method_name.startswith("_") and method_name not in BRIDGES:
                        yield f"{module_name}.{name}.{method_name}", method


def test_the_check_finds_a_message_where_there_is_one():
    assert messages_in(typing.Optional[scene_pb2.Scene]) == [scene_pb2.Scene]
    assert messages_in(typing.Callable[[common_pb2.Body], None]) == [common_pb2.Body]
    assert messages_in(typing.Dict[str, typing.List[common_pb2.Pose]]) == [common_pb2.Pose]
    assert not messages_in(graspsim.SceneLike) and not messages_in(graspsim.PoseLike)


def test_no_public_annotation_names_a_protobuf_message():
    names = type_checking_names()
    checked, offenders = 0, []
    for where, function in public_callables():
        module = sys.modules[function.__module__]
        hints = typing.get_type_hints(function, globalns={**vars(module), **names})
        checked += 1
        offenders += [f"{where}: {parameter} -> {message.DESCRIPTOR.full_name}"
                      for parameter, hint in hints.items() for message in messages_in(hint)]
    assert checked > 100, "the whole public API, not an empty walk"
    assert not offenders, "protobuf messages in the public API:\n" + "\n".join(offenders)


def no_message_inside(value, where: str = "reply") -> list:
    """Where, in a reply, a Message sits: through dataclasses, lists, tuples, dicts."""
    if isinstance(value, Message):
        return [f"{where}: {type(value).__name__}"]
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return [m for f in dataclasses.fields(value)
                for m in no_message_inside(getattr(value, f.name), f"{where}.{f.name}")]
    if isinstance(value, dict):
        return [m for key, item in value.items() for m in no_message_inside(item, f"{where}[{key!r}]")]
    if isinstance(value, (list, tuple)):
        return [m for i, item in enumerate(value) for m in no_message_inside(item, f"{where}[{i}]")]
    return []


def assert_reply(value, kind):
    assert isinstance(value, kind), f"{type(value).__name__}, expected {kind}"
    found = no_message_inside(value)
    assert not found, f"protobuf messages in a reply: {found}"


def test_replies_of_the_scene_service_are_dataclasses(client, start_server, tmp_path):
    scene = client.create_scene("public types")
    assert_reply(scene, graspsim.SceneSummary)
    try:
        assert_reply(client.list_scenes(), list)
        assert all(isinstance(s, graspsim.SceneSummary) for s in client.list_scenes())
        assert_reply(client.builtin_models()[0], graspsim.BuiltinModel)
        assert_reply(client.upload_file(scene, "meshes/cube.stl", cube_stl()), graspsim.FileInfo)
        vertices, triangles = meshes.uv_sphere(0.02, 6, 8)
        ball = client.add_object(scene, "ball", mesh=(vertices, triangles), mass=0.1, pose=[0, 0, 1, 1, 0, 0, 0])
        assert_reply(ball, graspsim.Body)
        assert_reply(client.add_object(scene, "cube", mesh_file="meshes/cube.stl", is_static=True), graspsim.Body)
        robot = client.add_robot(scene, "pg70", builtin="schunk_pg70", base_pose=[0, 0, 0.5, 1, 0, 0, 0])
        assert_reply(robot, graspsim.AddedRobot)
        assert_reply(client.step_simulation(scene, steps=2), graspsim.StepResult)
        assert_reply(client.set_simulation_params(scene, gravity=[0, 0, -9.8]), graspsim.SimulationParams)
        assert_reply(client.get_simulation_params(scene), graspsim.SimulationParams)
        full = client.get_scene(scene, include_geometry=True)
        assert_reply(full, graspsim.Scene)
        assert {b.motion for b in full.bodies} == {"free", "static", "articulated"}
        assert next(b for b in full.bodies if b.id == "ball").collision[0].vertices.shape == vertices.shape
        # The objects of the replies name what they carry: a Body its body, a Scene or a summary its scene.
        assert client.set_body_pose(full, ball, [0, 0, 2, 1, 0, 0, 0]) > 0
        assert client.get_body_poses(scene.id, ["ball"])["ball"].position[2] == 2.0
        with pytest.raises(TypeError, match="scene_id: a scene id"):
            client.get_scene(ball)   # a Body is no scene, though it has an .id
        with pytest.raises(TypeError, match="body_id: a body id"):
            client.set_body_pose(scene, scene, [0, 0, 2, 1, 0, 0, 0])
        assert_reply(client.whoami(), graspsim.Identity)
        archive = client.export_scene(scene)
    finally:
        client.delete_scene(scene)
    other = start_server(f"--data-dir={tmp_path / 'other'}")
    with graspsim.connect(other.address) as there:
        assert_reply(there.import_scene(archive), graspsim.SceneSummary)


def test_replies_of_grasps_and_motion_are_dataclasses_and_arrays(client, scene_id):
    candidate = graspsim.GraspCandidate([0, 0, -1], [0, 0, 0.025], [1, 0, 0], preshape="power")
    row, contacts = client.evaluate_grasp("schunk_pg70", candidate, mesh=meshes.box_mesh([0.04, 0.04, 0.05]))
    assert isinstance(row, np.void) and isinstance(contacts, np.ndarray) and row["outcome"] == "grasp"
    with pytest.raises(TypeError, match="candidate: a GraspCandidate"):
        client.evaluate_grasp("schunk_pg70", {"approach": [0, 0, -1]}, mesh=meshes.box_mesh([0.04] * 3))
    client.add_object(scene_id, "table", builtin="table")
    cube = client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0.05, 0.2, 0.775, 1, 0, 0, 0])
    client.add_robot(scene_id, "kr5", builtin="kuka_kr5_sixx_r850_pg70", base_pose=[-0.45, 0, 0.75, 1, 0, 0, 0])
    with client.pick_and_place_stream(scene_id, "kr5", cube, [0.05, -0.2, 0.775, 1, 0, 0, 0]) as stream:
        first = next(stream)
    assert_reply(first, graspsim.PickAndPlaceProgress)
    assert first.stage and first.result is None


def test_replies_of_the_gateway_are_dataclasses(start_server, tmp_path):
    """On a server of its own: the e-stop of every device must not reach another test's gateway."""
    rig_module = pytest.importorskip("graspsim.testing.gateway_rig")
    try:
        rig_module.find_bin_dir()
    except FileNotFoundError as err:
        pytest.skip(str(err))
    server = start_server()
    with graspsim.connect(server.address) as own, \
            rig_module.GatewayRig(server.address, kinds=["pg70"], name="types", log_path=tmp_path / "gw.log") as rig:
        devices = rig.wait_for_devices(own)
        assert_reply(devices, list)
        assert all(isinstance(d, graspsim.Device) for d in devices)
        assert_reply(own.list_devices()[0], graspsim.Device)
        assert_reply(own.send_command("pg70", read=True), graspsim.CommandResult)
        twin = own.create_scene("twin")
        own.add_robot(twin, "twin", builtin="schunk_pg70")
        samples = []
        result = own.predict_action("pg70", twin, "twin", 0.05, 0.04, 80, rate_hz=20, on_sample=samples.append)
        assert_reply(result, graspsim.PredictionResult)
        assert samples and all(isinstance(s, graspsim.PredictionSample) and not no_message_inside(s) for s in samples)
        assert_reply(own.emergency_stop(), graspsim.EmergencyStopResult)


SNIPPET_OK = '''
import graspsim

def use(client: graspsim.Client) -> float:
    summary = client.create_scene("typed")
    body = client.add_object(summary, "ball", sphere=0.02, mass=0.1)
    scene = client.get_scene(summary)
    client.set_body_pose(scene, body, [0, 0, 1, 1, 0, 0, 0])
    replay = client.replay_recording("run.mcap")
    client.step_simulation(replay, steps=1)
    client.plan_grasps("schunk_pg70", scene_id=summary, body_id=body)
    params: graspsim.SimulationParams = client.get_simulation_params(summary.id)
    return float(params.gravity[2]) + float(body.pose.position[2])
'''
SNIPPET_BODY_AS_SCENE = '''
import graspsim

def use(client: graspsim.Client) -> None:
    body = client.add_object("scene-1", "ball", sphere=0.02, mass=0.1)
    client.get_scene(body)
'''


@pytest.mark.skipif(sys.version_info < (3, 10), reason="the pinned mypy (the client's test extra) needs Python >= 3.10")
def test_mypy_takes_the_objects_that_carry_an_id_and_tells_a_body_from_a_scene(tmp_path):
    """SceneLike and BodyLike as a mypy --strict user sees them (run from clients/python: its configuration and
    cache)."""
    def mypy(code: str):
        path = tmp_path / "snippet.py"
        path.write_text(code)
        return subprocess.run([sys.executable, "-m", "mypy", "--strict", str(path)], cwd=CLIENT, capture_output=True,
                              text=True, timeout=600)
    ok = mypy(SNIPPET_OK)
    assert ok.returncode == 0, ok.stdout + ok.stderr
    refused = mypy(SNIPPET_BODY_AS_SCENE)
    assert refused.returncode == 1 and '"get_scene" of "Client" has incompatible type "Body"' in refused.stdout, \
        refused.stdout
