"""The browser viewer's HTTP routes (GET /view...) against the real server, without a browser; and the Python
helpers graspsim.viewer_url and graspsim.viewer (matplotlib snapshot view)."""
import base64
import json
import socket
import threading
import time
import urllib.error
import urllib.request

import numpy as np
import pytest

import graspsim
from graspsim.testing import partial_view

CUBE = 0.05  # m


def get(server, path: str):
    """GETs from the HTTP port; returns (http_status, content_type, text)."""
    try:
        with urllib.request.urlopen(f"{server.http_url}{path}", timeout=20) as response:
            return response.status, response.headers.get("Content-Type"), response.read().decode()
    except urllib.error.HTTPError as error:
        return error.code, error.headers.get("Content-Type"), error.read().decode()


class Events:
    """A Server-Sent Events stream read line by line: next() -> (event, data dict)."""

    def __init__(self, server, path: str):
        self.response = urllib.request.urlopen(f"{server.http_url}{path}", timeout=30)
        assert self.response.headers.get("Content-Type").startswith("text/event-stream")

    def next(self):
        event, data = None, None
        while True:
            line = self.response.readline().decode()
            assert line, "the event stream ended"
            line = line.rstrip("\n")
            if line.startswith("event: "):
                event = line[7:]
            elif line.startswith("data: "):
                data = json.loads(line[6:])
            elif line == "" and event:
                return event, data

    def close(self):
        self.response.close()


@pytest.fixture
def cube_scene(client, scene_id):
    client.add_object(scene_id, "cube", box=(CUBE, CUBE, CUBE), mass=0.1, pose=[0.1, -0.2, 0.3, 1, 0, 0, 0])
    return scene_id


def test_scene_list_links_every_scene(server, client, cube_scene):
    status, content_type, text = get(server, "/view")
    assert status == 200 and content_type.startswith("text/html")
    assert f'<a href="/view/{cube_scene}">{cube_scene}</a>' in text
    assert get(server, "/view/")[0] == 200


@pytest.mark.parametrize("path", ["/view/no-such-scene", "/view/no-such-scene/scene.json", "/view/no-such-scene/poses",
                                  "/view/no-such-scene/tactile"])
def test_unknown_scene_is_404_naming_it(server, path):
    status, content_type, text = get(server, path)
    assert status == 404 and content_type == "application/json"
    body = json.loads(text)
    assert body["status"] == "NOT_FOUND" and "'no-such-scene'" in body["message"]


def test_page_and_bundle_are_served(server, cube_scene):
    status, content_type, page = get(server, f"/view/{cube_scene}")
    assert status == 200 and content_type.startswith("text/html")
    assert 'src="/view/assets/viewer.js"' in page
    status, content_type, script = get(server, "/view/assets/viewer.js")
    assert status == 200 and "javascript" in content_type
    assert len(script) > 100_000  # three.js is bundled in, not fetched from elsewhere
    assert "http://" not in page and "https://" not in page
    assert get(server, "/view/assets/no-such-file.js")[0] == 404


def test_scene_json_carries_the_geometry(server, cube_scene):
    status, _, text = get(server, f"/view/{cube_scene}/scene.json")
    assert status == 200
    body = {b["id"]: b for b in json.loads(text)["bodies"]}["cube"]
    assert body["collision"][0]["box"]["size"] == {"x": CUBE, "y": CUBE, "z": CUBE}
    assert body["pose"]["position"] == {"x": 0.1, "y": -0.2, "z": 0.3}


def test_poses_follow_the_scene_and_ids_come_once(server, client, cube_scene):
    events = Events(server, f"/view/{cube_scene}/poses?max_seconds=30")
    try:
        event, first = events.next()
        assert event == "snapshot" and first["body_ids"] == ["cube"]
        np.testing.assert_allclose(first["poses"], [0.1, -0.2, 0.3, 1, 0, 0, 0], atol=1e-7)
        q = graspsim.quaternion_about_axis([0, 0, 1], 0.5)
        revision = client.set_body_pose(cube_scene, "cube", [0.02, 0.03, 0.04, *q])
        while True:
            event, snapshot = events.next()
            assert event == "snapshot"
            if snapshot["revision"] >= revision:
                break
        assert "body_ids" not in snapshot  # the list goes out again only when it changes
        np.testing.assert_allclose(snapshot["poses"], [0.02, 0.03, 0.04, *q], atol=1e-6)
        client.add_object(cube_scene, "ball", sphere=0.01, mass=0.01, pose=[0, 0, 0.5, 1, 0, 0, 0])
        event, snapshot = events.next()
        assert snapshot["body_ids"] == ["cube", "ball"] and len(snapshot["poses"]) == 14
    finally:
        events.close()


def test_a_viewer_joining_a_watched_scene_gets_the_body_ids_first(server, client, cube_scene):
    """Viewers asking the same share one encoded stream; one that joins late still gets the id list first."""
    path = f"/view/{cube_scene}/poses?max_seconds=30"
    watching, joining = Events(server, path), None
    try:
        assert watching.next()[1]["body_ids"] == ["cube"]
        revision = client.set_body_pose(cube_scene, "cube", [0.05, 0, 0.3, 1, 0, 0, 0])
        while (snapshot := watching.next()[1])["revision"] < revision:
            pass
        assert "body_ids" not in snapshot  # the stream's newest event carries no ids
        joining = Events(server, path)
        event, first = joining.next()
        assert event == "snapshot" and first["body_ids"] == ["cube"] and first["revision"] >= revision
        np.testing.assert_allclose(first["poses"], [0.05, 0, 0.3, 1, 0, 0, 0], atol=1e-7)
    finally:
        watching.close()
        if joining:
            joining.close()


def test_stream_ends_with_a_status_after_max_seconds(server, cube_scene):
    events = Events(server, f"/view/{cube_scene}/poses?max_seconds=0.5")
    try:
        assert events.next()[0] == "snapshot"
        event, status = events.next()
        assert event == "status" and status["status"] == "OK"
    finally:
        events.close()


@pytest.mark.parametrize("query, field", [("max_rate_hz=abc", "max_rate_hz"), ("max_rate_hz=-1", "max_rate_hz"),
                                          ("max_seconds=0", "max_seconds")])
def test_bad_parameters_name_the_parameter(server, cube_scene, query, field):
    status, _, text = get(server, f"/view/{cube_scene}/poses?{query}")
    assert status == 400 and json.loads(text)["message"].startswith(f"{field}: ")


def test_grasps_need_a_known_set_id(server, cube_scene):
    status, _, text = get(server, f"/view/{cube_scene}/grasps")
    assert status == 400 and json.loads(text)["message"].startswith("set_id: ")
    status, _, text = get(server, f"/view/{cube_scene}/grasps?set_id={'ab' * 32}")
    assert status == 404 and "ab" * 32 in json.loads(text)["message"]


def test_tactile_stream_of_a_scene_without_pads_is_404(server, cube_scene):
    status, _, text = get(server, f"/view/{cube_scene}/tactile")
    assert status == 404 and "no tactile arrays" in json.loads(text)["message"]


def test_tactile_stream_reads_every_pad(server, client, scene_id):
    client.add_robot(scene_id, "cell", builtin="schunk_pg70_on_z_axis", base_pose=[0, 0, 1.05, 1, 0, 0, 0])
    arrays = {a.id: a for a in client.get_scene(scene_id).tactile_arrays}
    assert len(arrays) == 2
    events = Events(server, f"/view/{scene_id}/tactile?max_seconds=30")
    try:
        seen = {}
        while len(seen) < len(arrays):
            event, reading = events.next()
            assert event == "reading"
            seen[reading["sensor_id"]] = reading
    finally:
        events.close()
    for sensor_id, reading in seen.items():
        array = arrays[sensor_id]
        assert (reading["rows"], reading["cols"]) == (array.rows, array.cols)
        assert len(reading["intensities"]) == array.rows * array.cols
        assert reading["intensity_sum"] == sum(reading["intensities"]) == 0  # nothing touches the open pads


@pytest.mark.parametrize("stalled_rate_hz", [1000, 30])  # 30: the same stream as the reading viewer's
def test_a_stalled_viewer_does_not_stop_the_others(server, client, scene_id, stalled_rate_hz):
    """One viewer never reads its socket while the scene steps; another still gets the newest snapshots."""
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, 0.75 + CUBE / 2, 1, 0, 0, 0])
    cube_scene = scene_id
    host, port = server.http_url.removeprefix("http://").split(":")
    stalled = socket.create_connection((host, int(port)))
    stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    stalled.sendall(f"GET /view/{cube_scene}/poses?max_rate_hz={stalled_rate_hz} HTTP/1.1\r\nHost: x\r\n\r\n".encode())
    stop = threading.Event()

    def step():
        while not stop.is_set():
            client.step_simulation(cube_scene, 0.1)

    stepper = threading.Thread(target=step)
    stepper.start()
    events = Events(server, f"/view/{cube_scene}/poses?max_seconds=60")
    try:
        times = []
        while len(times) < 20:
            event, snapshot = events.next()
            times.append(snapshot["time"])
        assert times == sorted(times) and times[-1] > times[0]
    finally:
        stop.set()
        stepper.join()
        events.close()
        stalled.close()


def test_viewer_url():
    assert graspsim.viewer_url("scene-1") == "http://127.0.0.1:8080/view/scene-1"
    assert graspsim.viewer_url("a b", "http://h:9/", grasp_set="ff00", grasp_object="cube") == \
        "http://h:9/view/a%20b?grasp_set=ff00&grasp_object=cube"
    with pytest.raises(ValueError, match="empty scene id"):
        graspsim.viewer_url("")


def test_viewer_url_opens_the_page(server, client, cube_scene):
    url = graspsim.viewer_url(client.get_scene(cube_scene), server.http_url)
    with urllib.request.urlopen(url, timeout=20) as response:
        assert response.status == 200


def test_world_meshes_place_each_shape_at_its_body_pose(client, scene_id):
    q = graspsim.quaternion_about_axis([0, 0, 1], np.pi / 2)
    client.add_object(scene_id, "cube", box=(0.1, 0.02, 0.04), mass=0.1, pose=[1, 2, 3, *q])
    client.add_object(scene_id, "rod", cylinder=(0.01, 0.2), mass=0.1, pose=[0, 0, 1, 1, 0, 0, 0])
    shapes = graspsim.viewer.world_meshes(client.get_scene(scene_id, include_geometry=True))
    assert [s[0] for s in shapes] == ["cube", "rod"]
    cube = shapes[0][1]
    # Rotated 90° about z: the 0.1 m edge now lies along y, the 0.02 m edge along x.
    np.testing.assert_allclose(cube.min(0), [1 - 0.01, 2 - 0.05, 3 - 0.02], atol=1e-12)
    np.testing.assert_allclose(cube.max(0), [1 + 0.01, 2 + 0.05, 3 + 0.02], atol=1e-12)
    rod = shapes[1][1]
    np.testing.assert_allclose(np.linalg.norm(rod[:, :2], axis=1).max(), 0.01, rtol=1e-12)
    np.testing.assert_allclose([rod[:, 2].min(), rod[:, 2].max()], [0.9, 1.1], atol=1e-12)


def test_scene_figure_draws_every_shape(client, scene_id):
    pytest.importorskip("matplotlib")
    client.add_object(scene_id, "cube", box=(CUBE, CUBE, CUBE), mass=0.1, pose=[0, 0, 0.5, 1, 0, 0, 0])
    client.add_object(scene_id, "ball", sphere=0.02, mass=0.1, pose=[0.2, 0, 0.5, 1, 0, 0, 0])
    fig = graspsim.viewer.scene_figure(client, scene_id)
    ax = fig.axes[0]
    assert len(ax.collections) == 2
    assert ax.get_xlim()[0] <= -CUBE / 2 + 1e-12 and ax.get_xlim()[1] >= 0.22 - 1e-12  # both bodies inside
    fig.canvas.draw()  # renders without a display


@pytest.fixture
def resting_cube(client, scene_id):
    """The built-in 5 cm cube resting on the table after 1 s of simulation, kept awake (a sleeping body's contacts
    are not computed, so a snapshot then has none)."""
    client.set_simulation_params(scene_id, sleep_time=100.0)
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, 0.75 + CUBE / 2, 1, 0, 0, 0])
    client.step_simulation(scene_id, 1.0)
    return scene_id


def force_on(snapshot_contacts, pairs, body: int) -> np.ndarray:
    """Sum of the contact forces acting on one body: +f where it is the first body, -f where the second."""
    sign = (pairs[:, 0] == body).astype(float) - (pairs[:, 1] == body)
    return (sign[:, None] * snapshot_contacts[:, 3:]).sum(axis=0)


def test_snapshot_contacts_hold_the_resting_cube_up(client, resting_cube):
    mass = next(b for b in client.get_scene(resting_cube).bodies if b.id == "cube").inertial.mass
    with client.watch_scene(resting_cube) as watch:
        snapshot = next(iter(watch))
    assert len(snapshot.contacts) >= 4  # at least the cube's bottom corners
    cube = snapshot.body_ids.index("cube")
    # At rest the contacts carry the weight: Σ f = (0, 0, m g) on the cube, within 1 %.
    np.testing.assert_allclose(force_on(snapshot.contacts, snapshot.contact_bodies, cube), [0, 0, mass * 9.81],
                               rtol=0, atol=0.01 * mass * 9.81)
    # Every contact point lies on the table top, under the cube.
    np.testing.assert_allclose(snapshot.contacts[:, 2], 0.75, atol=1e-3)
    assert np.all(np.abs(snapshot.contacts[:, :2]) <= CUBE / 2 + 1e-3)
    client.set_body_pose(resting_cube, "cube", [0, 0, 0.9, 1, 0, 0, 0])  # lifted by hand: no contact until a step
    with client.watch_scene(resting_cube) as watch:
        assert len(next(iter(watch)).contacts) == 0


def test_pose_events_carry_contacts_when_asked(server, client, resting_cube):
    with client.watch_scene(resting_cube) as watch:
        reference = next(iter(watch))
    events = Events(server, f"/view/{resting_cube}/poses?contacts=1&max_seconds=30")
    try:
        event, snapshot = events.next()
    finally:
        events.close()
    contacts = np.frombuffer(base64.b64decode(snapshot["contacts_f32"]), dtype="<f4").reshape(-1, 6)
    np.testing.assert_allclose(contacts, reference.contacts, rtol=1e-6, atol=1e-9)  # float32
    pairs = np.frombuffer(base64.b64decode(snapshot["contact_bodies_u32"]), dtype="<u4").reshape(-1, 2)
    np.testing.assert_array_equal(pairs, reference.contact_bodies)
    events = Events(server, f"/view/{resting_cube}/poses?max_seconds=30")
    try:
        assert "contacts_f32" not in events.next()[1]
    finally:
        events.close()
    status, _, text = get(server, f"/view/{resting_cube}/poses?contacts=yes")
    assert status == 400 and json.loads(text)["message"].startswith("contacts: 'yes'")


def test_overlays_of_a_fresh_scene_are_empty_and_unknown_scenes_404(server, scene_id):
    status, _, text = get(server, f"/view/{scene_id}/overlays.json")
    assert status == 200 and json.loads(text) == {"version": 0, "completion": None, "arm_path": None}
    status, _, text = get(server, "/view/no-such-scene/overlays.json")
    assert status == 404 and "no-such-scene" in json.loads(text)["message"]


def test_overlays_carry_the_last_arm_path_and_completion(server, client, scene_id):
    """The tip path starts at the flange's pose in the scene and ends on the goal; the completion's plane and body
    are those CompleteShape answered."""
    table = 0.75
    client.add_object(scene_id, "table", builtin="table")
    client.add_robot(scene_id, "pa10", builtin="mitsubishi_pa10_pg70", base_pose=[-0.45, 0, table, 1, 0, 0, 0])
    start = client.get_body_poses(scene_id, ["pa10/flange"])["pa10/flange"].position
    goal = [0.1, -0.1, table + 0.30, 0, 1, 0, 0]
    path = client.plan_arm_path(scene_id, "pa10", goal=goal)
    overlays = json.loads(get(server, f"/view/{scene_id}/overlays.json")[2])
    arm = overlays["arm_path"]
    assert arm["arm_id"] == "pa10" and arm["tip_body"] == path.tip_body == "pa10/flange"
    assert arm["duration"] == pytest.approx(path.duration, rel=1e-8)  # 9 digits in the JSON
    assert len(arm["tip_points"]) == 1 + 8 * (path.waypoints.shape[0] - 1)
    np.testing.assert_allclose(arm["tip_points"][0], start, atol=1e-6)
    np.testing.assert_allclose(arm["tip_points"][-1], goal[:3], atol=1e-6)
    assert overlays["completion"] is None

    vertices, triangles = partial_view.cylinder_mesh(0.04, 0.10, 48)
    vertices = vertices + [0.1, 0.2, table]
    centre = np.array([0.1, 0.2, table + 0.05])
    camera = partial_view.look_at(centre + 0.5 * np.array([0.87, 0.0, 0.5]), centre)
    intrinsics = (150.0, 150.0, 79.5, 59.5)
    depth, mask = partial_view.render_depth(vertices, triangles, camera, 160, 120, *intrinsics)
    shape = client.complete_shape(camera, depth=depth, intrinsics=intrinsics, mask=mask, orientations=1,
                                  table_pose=[0, 0, table, 1, 0, 0, 0], add_to_scene_id=scene_id, object_name="can")
    later = json.loads(get(server, f"/view/{scene_id}/overlays.json")[2])
    assert later["version"] > overlays["version"] and later["arm_path"] == arm
    completion = later["completion"]
    assert completion["body_id"] == shape.body_id == "can"
    np.testing.assert_allclose(completion["normal"], shape.plane_normal, atol=1e-6)
    np.testing.assert_allclose(completion["point"], shape.plane_point, atol=1e-6)
    assert 0.1 < completion["size"] < 0.2  # the completed can's diagonal: about sqrt(0.08² · 2 + 0.1²) = 0.15
