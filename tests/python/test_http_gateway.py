"""The HTTP/JSON gateway against the real server: POST /v1/<Service>/<Method> reaches the same services as gRPC."""
import base64
import hashlib
import json
import threading
import time
import urllib.error
import urllib.parse
import urllib.request

import numpy as np
import pytest

from graspsim import meshes
from graspsim.v1 import gateway_pb2, grasp_pb2, perception_pb2, recording_pb2, scene_pb2, tactile_pb2

from _support import whole_scene


def post(server, path: str, body=None, *, form: bool = False, query: str = ""):
    """POSTs to the gateway; returns (http_status, content_type, text). body: dict/list → JSON (or payload=)."""
    text = json.dumps(body if body is not None else {})
    if form:
        data = urllib.parse.urlencode({"payload": text}).encode()
        content_type = "application/x-www-form-urlencoded"
    else:
        data, content_type = text.encode(), "application/json"
    url = f"{server.http_url}/v1/{path}" + (f"?{query}" if query else "")
    request = urllib.request.Request(url, data=data, headers={"Content-Type": content_type}, method="POST")
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return response.status, response.headers.get("Content-Type"), response.read().decode()
    except urllib.error.HTTPError as error:
        return error.code, error.headers.get("Content-Type"), error.read().decode()


def call(server, path, body=None, **kwargs):
    status, _, text = post(server, path, body, **kwargs)
    assert status == 200, text
    return json.loads(text)


def sse_events(text: str):
    """[(event, data dict)] of a Server-Sent Events body."""
    events = []
    for block in text.strip().split("\n\n"):
        fields = dict(line.split(": ", 1) for line in block.split("\n"))
        events.append((fields["event"], json.loads(fields["data"])))
    return events


def test_every_api_method_is_listed_and_reachable_without_per_method_code(server):
    with urllib.request.urlopen(f"{server.http_url}/v1", timeout=10) as response:
        listed = {(s["name"], m["name"]) for s in json.load(response)["services"] for m in s["methods"]}
    declared = {(service.full_name, method.name)
                for module in (scene_pb2, perception_pb2, grasp_pb2, tactile_pb2, gateway_pb2, recording_pb2)
                for service in module.DESCRIPTOR.services_by_name.values() for method in service.methods}
    assert listed == declared
    for service, method in declared:
        status, _, text = post(server, f"{service}/{method}", [] if method == "UploadFile" else {},
                               query="max_messages=1&max_seconds=1")
        # The service answers (often with its own error for the empty request); the gateway never says "no method".
        assert "no method" not in text, f"{service}/{method} is not reachable: {text}"


def test_json_and_form_bodies_reach_the_same_scene_service_as_grpc(server, client):
    created = call(server, "SceneService/CreateScene", {"name": "over http"})
    scene = created["summary"]["id"]
    assert created["summary"]["revision"] == "0"  # uint64 as a string, protobuf's JSON mapping
    body = call(server, "graspsim.v1.SceneService/AddObject",
                {"scene_id": scene, "name": "cube", "builtin": "cube_5cm",
                 "pose": {"position": {"z": 0.775}}}, form=True)
    assert body["motion"] == "BODY_MOTION_FREE" and body["inertial"]["mass"] == pytest.approx(0.1)
    pose = client.get_body_poses(scene, ["cube"])["cube"]
    np.testing.assert_allclose(pose.position, [0, 0, 0.775], atol=1e-12)


def test_errors_carry_code_message_and_http_status_and_change_nothing(server, client, scene_id):
    client.add_object(scene_id, "cube", builtin="cube_5cm")
    before = whole_scene(client, scene_id)
    bad_pose = {"scene_id": scene_id, "poses": [{"body_id": "cube", "pose": {"orientation": {"w": 2}}}]}
    status, content_type, text = post(server, "SceneService/SetBodyPoses", bad_pose)
    error = json.loads(text)
    assert (status, error["code"], error["status"]) == (400, 3, "INVALID_ARGUMENT")
    assert content_type.startswith("application/json")
    assert "poses[0].pose.orientation" in error["message"] and "norm 2" in error["message"]
    assert whole_scene(client, scene_id) == before

    status, _, text = post(server, "SceneService/GetScene", {"scene_id": "no-such-scene"})
    assert (status, json.loads(text)["status"]) == (404, "NOT_FOUND")
    status, _, text = post(server, "SceneService/AddObject", {"scene_id": scene_id, "name": "cube", "builtin": "cube_5cm"})
    assert (status, json.loads(text)["status"]) == (409, "ALREADY_EXISTS")
    status, _, text = post(server, "SceneService/CreateScene", {"nmae": "typo"})
    assert status == 400 and "nmae" in json.loads(text)["message"]
    status, _, text = post(server, "SceneService/NoSuchMethod")
    assert status == 404 and "SceneService/NoSuchMethod" in json.loads(text)["message"]
    status, _, text = post(server, "PerceptionService/SegmentScene", {})  # built: an empty cloud is named
    assert status == 400 and "cloud.points" in json.loads(text)["message"]
    status, _, text = post(server, "GatewayService/Connect", {})
    assert status == 501 and "bidirectional" in json.loads(text)["message"]


def test_large_form_bodies_are_accepted(server, client, scene_id):
    """Octave sends every request as a form; a mesh of ~3000 triangles is a ~77 kB payload (httplib alone: 8 kB)."""
    vertices, triangles = meshes.uv_sphere(0.03, 40, 40)
    packed = meshes.pack_mesh(vertices, triangles)
    request = {"scene_id": scene_id, "name": "ball",
               "geometry": {"mesh": {"vertices": base64.b64encode(packed.vertices).decode(),
                                     "triangles": base64.b64encode(packed.triangles).decode()}},
               "inertial": {"mass": 0.1, "ixx": 3.6e-5, "iyy": 3.6e-5, "izz": 3.6e-5}}
    assert len(urllib.parse.urlencode({"payload": json.dumps(request)})) > 50_000
    body = call(server, "SceneService/AddObject", request, form=True, query="envelope=1")
    assert body["code"] == 0, body
    assert body["response"]["triangle_count"] == len(triangles)


def test_envelope_answers_200_with_the_status_inside(server, scene_id):
    ok = call(server, "SceneService/GetScene", {"scene_id": scene_id}, query="envelope=1", form=True)
    assert (ok["code"], ok["status"]) == (0, "OK") and ok["response"]["summary"]["id"] == scene_id
    failed = call(server, "SceneService/GetScene", {"scene_id": "nope"}, query="envelope=1", form=True)
    assert (failed["code"], failed["status"]) == (5, "NOT_FOUND") and "nope" in failed["message"]


def test_client_stream_upload_takes_a_json_array(server, client, scene_id):
    data = meshes.to_stl(*meshes.box_mesh((0.02, 0.02, 0.02)))
    half = len(data) // 2
    chunks = [{"header": {"scene_id": scene_id, "path": "box.stl", "total_size": str(len(data)),
                          "sha256": hashlib.sha256(data).hexdigest()},
               "data": base64.b64encode(data[:half]).decode()},
              {"data": base64.b64encode(data[half:]).decode()}]
    info = call(server, "SceneService/UploadFile", chunks)
    assert info["size"] == str(len(data))
    body = client.add_object(scene_id, "box", mesh_file="box.stl", mass=0.1, inertia=np.eye(3) * 1e-5)
    assert body.triangle_count == 12


def test_server_stream_as_server_sent_events(server, client, scene_id):
    client.add_object(scene_id, "cube", builtin="cube_5cm")
    revision = {}

    def move_later():
        time.sleep(0.5)
        revision["r"] = client.set_body_poses(scene_id, {"cube": [0, 0, 1, 1, 0, 0, 0]})

    mover = threading.Thread(target=move_later)
    mover.start()
    status, content_type, text = post(server, "SceneService/WatchScene", {"scene_id": scene_id},
                                      query="max_messages=2")
    mover.join()
    assert status == 200 and content_type.startswith("text/event-stream")
    events = sse_events(text)
    assert [name for name, _ in events] == ["message", "message", "status"]
    last = events[1][1]
    assert int(last["revision"]) == revision["r"]
    poses = np.frombuffer(base64.b64decode(last["body_poses"]), "<f8").reshape(-1, 7)
    np.testing.assert_allclose(poses[last["body_ids"].index("cube")], [0, 0, 1, 1, 0, 0, 0])
    assert events[2][1]["code"] == 0


def test_envelope_stream_collects_messages_until_max_seconds(server, scene_id):
    started = time.monotonic()
    body = call(server, "SceneService/WatchScene", {"scene_id": scene_id}, query="envelope=1&max_seconds=0.5")
    assert 0.4 < time.monotonic() - started < 5
    assert body["code"] == 0 and len(body["responses"]) == 1
    assert body["responses"][0]["body_ids"] == []
