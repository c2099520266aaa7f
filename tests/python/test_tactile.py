"""TactileService through the real server: the PG70's pads and gripper state, images, streams, errors."""
import base64
import json
import struct
import threading
import time
import urllib.request

import grpc
import numpy as np
import pytest

import graspsim
from graspsim.v1 import tactile_pb2, tactile_pb2_grpc

from _support import IA, assert_rejected, expect_error, two_link_urdf

TABLE_TOP = 0.75          # m, built-in table
CUBE = 0.05               # m, built-in cube_5cm edge
DOWN = (0, 1, 0, 0)       # (w, x, y, z): half a turn about x, the gripper's approach (+z) along world -z
LEFT = "pg70/finger_left_joint"
PADS = ("pg70/pad_left", "pg70/pad_right")


@pytest.fixture
def pg70(client, scene_id):
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70")
    return scene_id


def png_size(png: bytes):
    """(width, height) from a PNG's IHDR chunk, after checking the signature."""
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert png[12:16] == b"IHDR"
    return struct.unpack(">II", png[16:24])


def test_untouched_pads_read_zero(client, pg70):
    for pad in PADS:
        frame = client.sample(pg70, pad)
        assert isinstance(frame, graspsim.TactileFrame)
        assert (frame.sensor_id, frame.rows, frame.cols, frame.time) == (pad, 14, 6, 0.0)
        assert frame.intensities.shape == (14, 6) and frame.intensities.dtype == np.uint16
        assert frame.forces.shape == (14, 6, 3) and frame.forces.dtype == np.float32
        assert not frame.intensities.any() and not frame.forces.any()
        assert frame.intensity_sum == 0 and not frame.force_sum.any()


def test_tactile_image_png(client, pg70):
    assert png_size(client.tactile_image(pg70, "pg70/pad_left", scale=10)) == (60, 140)
    assert png_size(client.tactile_image(pg70, "pg70/pad_right")) == (120, 280)
    raw = client.tactile_stub.GetTactileImage(tactile_pb2.GetTactileImageRequest(
        scene_id=pg70, sensor_id="pg70/pad_left", scale=0), timeout=10)
    assert (raw.width, raw.height) == (120, 280) == png_size(raw.png), "scale 0 is the default 20"
    assert png_size(client.tactile_image(pg70, "pg70/pad_left", scale=292)) == (6 * 292, 14 * 292)


def test_gripper_reading_follows_joint_positions(client, pg70):
    client.set_joint_positions(pg70, {LEFT: 0.0125})
    reading = client.sample(pg70, "pg70/gripper")
    assert isinstance(reading, graspsim.GripperState)
    assert reading.finger_distance == pytest.approx(0.025, abs=1e-12), "2 q: the right finger mimics the left"
    assert (reading.motor_current, reading.finger_velocity) == (0.0, 0.0)


def test_gripper_reading_of_a_driven_finger(client, pg70):
    client.set_joint_positions(pg70, {LEFT: 0.03})
    client.set_actuator(pg70, LEFT, "velocity", -0.02, current_limit=2.0)
    client.step_simulation(pg70, duration=0.3)
    reading = client.sample(pg70, "pg70/gripper")
    assert reading.time == pytest.approx(0.3, abs=1e-9)
    assert reading.motor_current != 0.0
    assert reading.finger_velocity == pytest.approx(-0.02, abs=1e-3)
    assert reading.finger_distance == pytest.approx(2 * client.get_joint_positions(pg70)[LEFT], abs=1e-12)
    assert reading.finger_distance < 0.06, "closing"


def test_stream_follows_the_simulation(client, pg70):
    client.set_joint_positions(pg70, {LEFT: 0.03})
    client.set_actuator(pg70, LEFT, "velocity", -0.02, current_limit=2.0)
    errors = []

    def step():
        try:
            for _ in range(20):
                client.step_simulation(pg70, duration=0.01)
                time.sleep(0.02)
        except Exception as err:  # reported by the test thread
            errors.append(err)

    readings = []
    stepper = threading.Thread(target=step, daemon=True)
    with client.stream_sensors(pg70, ["pg70/gripper", "pg70/pad_left"], rate_hz=50) as stream:
        watchdog = threading.Timer(30, stream.cancel)  # a stream that stalls ends the loop instead of hanging
        watchdog.start()
        stepper.start()
        for reading in stream:
            readings.append(reading)
            if isinstance(reading, graspsim.TactileFrame) and reading.time >= 0.2 - 1e-9:
                break  # the last state's batch is complete
        watchdog.cancel()
    stepper.join(10)
    assert not errors, errors
    assert [r.sensor_id for r in readings] == ["pg70/gripper", "pg70/pad_left"] * (len(readings) // 2)
    grippers = [r for r in readings if isinstance(r, graspsim.GripperState)]
    times = [r.time for r in grippers]
    assert len(times) >= 3, times
    assert all(a < b for a, b in zip(times, times[1:])), f"a state is sent once, newest first: {times}"
    assert grippers[-1].finger_distance < grippers[0].finger_distance, "the fingers closed while streaming"
    assert all(isinstance(r, graspsim.TactileFrame) and r.rows == 14 for r in readings[1::2])


def test_stream_ends_when_the_scene_is_deleted(client):
    scene_id = client.create_scene("deleted while streaming").id
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70")
    with client.stream_sensors(scene_id, ["pg70/gripper"], rate_hz=10) as stream:
        assert next(stream).finger_distance == 0.0
        client.delete_scene(scene_id)
        with expect_error(grpc.StatusCode.UNAVAILABLE, scene_id, "deleted"):
            next(stream)


def test_stream_cancel_from_another_thread(client, pg70):
    stream = client.stream_sensors(pg70, PADS, rate_hz=20)
    assert [next(stream).sensor_id, next(stream).sensor_id] == list(PADS)
    timer = threading.Timer(0.2, stream.cancel)
    timer.start()
    assert list(stream) == []
    timer.join()


# A small stream window and no BDP probing: the never-reader's flow-control window fills after a few readings.
STALLED_CHANNEL_OPTIONS = [("grpc.http2.bdp_probe", 0), ("grpc.http2.lookahead_bytes", 16384)]


def test_a_reader_that_never_reads_slows_nothing(server, client, pg70):
    client.set_actuator(pg70, LEFT, "velocity", 0.02, current_limit=2.0)
    with grpc.insecure_channel(server.address, options=STALLED_CHANNEL_OPTIONS) as stalled_channel:
        stalled = tactile_pb2_grpc.TactileServiceStub(stalled_channel).Stream(
            tactile_pb2.StreamRequest(scene_id=pg70, sensor_ids=PADS, rate_hz=60), timeout=60)
        stalled.initial_metadata()  # accepted; never read
        with client.stream_sensors(pg70, ["pg70/gripper"], rate_hz=60) as live:
            next(live)
            started = time.monotonic()
            for _ in range(100):  # 100 revisions, each a new state for both streams
                client.step_simulation(pg70, steps=5)
            assert time.monotonic() - started < 10
            reading = next(live)
            while reading.time < 0.5 - 1e-9:  # the live reader catches up with the newest state
                reading = next(live)
    assert client.sample(pg70, "pg70/gripper").time == pytest.approx(0.5, abs=1e-9)


def test_unknown_sensors_are_not_found_and_list_the_available_ones(client, pg70):
    for bad in ("pg70/pad_middle", "pg70", "other/gripper"):
        err = assert_rejected(client, pg70, grpc.StatusCode.NOT_FOUND, ["sensor_id", bad, "pg70/pad_left",
                                                                        "pg70/gripper"],
                              lambda: client.sample(pg70, bad))
        assert "pg70/pad_right" in err.message
    assert_rejected(client, pg70, IA, ["sensor_id", "empty"], lambda: client.sample(pg70, ""))
    with expect_error(grpc.StatusCode.NOT_FOUND, "scene_id", "no-such-scene"):
        client.sample("no-such-scene", "pg70/pad_left")


def test_a_robot_without_prismatic_joints_has_no_gripper(client, scene_id):
    client.add_robot(scene_id, "arm", urdf=two_link_urdf())
    with expect_error(grpc.StatusCode.NOT_FOUND, "arm/gripper", "no prismatic joints", "available: arm/shoulder"):
        client.sample(scene_id, "arm/gripper")
    assert isinstance(client.sample(scene_id, "arm/shoulder"), graspsim.ForceTorqueState), "its joint's F/T sensor"


def test_a_joint_is_a_force_torque_sensor_reading_its_childs_weight(client, scene_id):
    # The PG70 pointing down, untouched: the left finger (0.05 kg, CoM (0, 10, 30) mm in its frame) hangs on its
    # joint, which carries -(m g) with the moment -(c x m g), both in the finger's frame (z along world -z).
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70", base_pose=graspsim.Pose([0, 0, 0.91], DOWN))
    before = client.sample(scene_id, LEFT)
    assert isinstance(before, graspsim.ForceTorqueState)
    assert (before.sensor_id, before.time) == (LEFT, 0.0)
    assert not before.force.any() and not before.torque.any(), "zero before the first step"
    client.step_simulation(scene_id, duration=0.05)
    reading = client.sample(scene_id, LEFT)
    weight = np.array([0, 0, 0.05 * 9.81])  # m g in the finger's frame: world -z is its +z
    np.testing.assert_allclose(reading.force, -weight, rtol=0, atol=1e-9)
    np.testing.assert_allclose(reading.torque, -np.cross([0, 0.010, 0.030], weight), rtol=0, atol=1e-9)
    assert reading.time == pytest.approx(0.05, abs=1e-9)
    with client.stream_sensors(scene_id, ["pg70/gripper", LEFT], rate_hz=10) as stream:
        gripper, streamed = next(stream), next(stream)
        assert isinstance(gripper, graspsim.GripperState) and isinstance(streamed, graspsim.ForceTorqueState)
        np.testing.assert_array_equal(streamed.force, reading.force)


def test_stream_request_errors_name_the_field(client, pg70):
    cases = [
        (dict(sensor_ids=["pg70/gripper"], rate_hz=0), IA, ["rate_hz", "0"]),
        (dict(sensor_ids=["pg70/gripper"], rate_hz=-5), IA, ["rate_hz", "-5"]),
        (dict(sensor_ids=["pg70/gripper"], rate_hz=float("nan")), IA, ["rate_hz", "nan"]),
        (dict(sensor_ids=["pg70/gripper"], rate_hz=61), IA, ["rate_hz", "61 Hz", "60 Hz", "--watch-max-rate-hz"]),
        (dict(sensor_ids=[], rate_hz=10), IA, ["sensor_ids", "empty"]),
        (dict(sensor_ids=[PADS[0], PADS[1], PADS[0]], rate_hz=10), IA, ["sensor_ids[2]", PADS[0], "twice"]),
        (dict(sensor_ids=["pg70/gripper", "pg70/nope"], rate_hz=10), grpc.StatusCode.NOT_FOUND,
         ["sensor_ids[1]", "pg70/nope", "pg70/pad_left"]),
    ]
    for kwargs, code, parts in cases:
        with expect_error(code, *parts):
            with client.stream_sensors(pg70, **kwargs) as stream:
                next(stream)
    with expect_error(grpc.StatusCode.NOT_FOUND, "scene_id", "no-such-scene"):
        next(client.stream_sensors("no-such-scene", ["pg70/gripper"], rate_hz=10))


def test_image_errors_name_the_field(client, pg70):
    assert_rejected(client, pg70, IA, ["scale", "293", "4096", "292", "pg70/pad_left"],
                    lambda: client.tactile_image(pg70, "pg70/pad_left", scale=293))
    assert_rejected(client, pg70, IA, ["sensor_id", "pg70/gripper", "not a tactile array"],
                    lambda: client.tactile_image(pg70, "pg70/gripper"))
    assert_rejected(client, pg70, IA, ["sensor_id", LEFT, "not a tactile array"],
                    lambda: client.tactile_image(pg70, LEFT))
    assert_rejected(client, pg70, grpc.StatusCode.NOT_FOUND, ["sensor_id", "pg70/pad"],
                    lambda: client.tactile_image(pg70, "pg70/pad"))


def http_post(server, path: str, body: dict, query: str = ""):
    """(content type, text) of a POST to the HTTP gateway."""
    request = urllib.request.Request(f"{server.http_url}/v1/{path}" + (f"?{query}" if query else ""),
                                     data=json.dumps(body).encode(), headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=10) as response:
        return response.headers.get("Content-Type"), response.read().decode()


def test_sample_and_stream_through_the_http_gateway(server, client, pg70):
    _, text = http_post(server, "TactileService/Sample", {"scene_id": pg70, "sensor_id": "pg70/pad_right"})
    tactile = json.loads(text)["tactile"]
    assert (tactile["rows"], tactile["cols"]) == (14, 6)
    assert base64.b64decode(tactile["intensities"]) == bytes(2 * 84)
    content_type, text = http_post(server, "TactileService/Stream",
                                   {"scene_id": pg70, "sensor_ids": ["pg70/gripper", "pg70/pad_left"],
                                    "rate_hz": 10}, query="max_messages=2")
    assert content_type.startswith("text/event-stream")
    events = [block.split("\n") for block in text.strip().split("\n\n")]
    assert [e[0] for e in events] == ["event: message", "event: message", "event: status"]
    assert "gripper" in json.loads(events[0][1][len("data: "):])


def test_open_streams_end_when_the_server_stops(start_server):
    proc = start_server()
    with graspsim.connect(proc.address) as client:
        scene_id = client.create_scene().id
        client.add_robot(scene_id, "pg70", builtin="schunk_pg70")
        stream = client.stream_sensors(scene_id, PADS, rate_hz=10)
        next(stream)
        assert proc.stop() == 0
        with pytest.raises(graspsim.GraspsimError):
            list(stream)


def test_pg70_closing_on_the_cube_presses_both_pads(client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70", base_pose=graspsim.Pose([0, 0, 0.91], DOWN))
    client.set_joint_positions(scene_id, {LEFT: 0.03})
    client.set_actuator(scene_id, LEFT, "velocity", -0.05, current_limit=2.0)
    client.step_simulation(scene_id, duration=0.8)
    left, right = (client.sample(scene_id, pad) for pad in PADS)
    for frame in (left, right):
        assert frame.intensity_sum > 0, f"{frame.sensor_id} reads nothing"
        # The force on the pad, pad frame: the cube pushes it along its -z (+z points at what it touches).
        assert frame.force_sum[2] < 0, f"{frame.sensor_id}: the cube presses the pad"
    assert left.intensity_sum == pytest.approx(right.intensity_sum, rel=0.2), (left.intensity_sum,
                                                                              right.intensity_sum)
    png = client.tactile_image(scene_id, PADS[0], scale=10)
    assert png_size(png) == (60, 140)
    # The left finger's joint presses it on the cube: along the finger axis (its frame's y, closing = -y) it
    # transmits the grip force, which the left pad feels as its normal force.
    wrench = client.sample(scene_id, LEFT)
    grip = abs(left.force_sum[2])
    assert grip > 1.0, grip
    assert wrench.force[1] < 0, wrench.force
    assert -wrench.force[1] == pytest.approx(grip, rel=0.05), (wrench.force, left.force_sum)
