"""RecordingService through the real server (issue 25, docs/recording.md): a work cycle recorded as MCAP and its
contents checked with the field's own readers, not only ours: mcap's seeking reader, classes built from the schemas
embedded in the file (mcap-protobuf-support), Foxglove's generated classes (foxglove-schemas-protobuf), rosbags for
the ROS 2 bag; listing and downloading while recording; bad requests.

Replays, --record, graspsim.mcap.compare and kill -9: test_recording_replay.py. A gateway action recorded beside
its twin: test_recording_gateway.py. Node's readers and the live Foxglove endpoint: test_recording_live.py.
Shared pieces (the work-cycle recording, channel tables, frame pairing): _recording_support.py.
"""
import os
import time
from collections import Counter, defaultdict
from pathlib import Path

import cbor2
import grpc
import numpy as np
import pytest
from google.protobuf.unknown_fields import UnknownFieldSet
from mcap.reader import SeekingReader, make_reader
from mcap_protobuf.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import Reader as Ros2Reader
from rosbags.typesys import Stores, get_typestore

import graspsim
import graspsim.mcap
from graspsim.v1 import common_pb2, recording_pb2, scene_pb2

from _recording_support import (EXACT, FOXGLOVE_CLASSES, FT_JOINT, NAME, NOT_FOUND, OWN_CLASSES, PADS, ROS2_TYPES,
                                SCHEMAS, keyed, stamp_ns, work_cycle_recording)
from _support import IA, expect_error


@pytest.fixture(scope="module")
def recorded(server, tmp_path_factory):
    """The work cycle recorded once on the shared server (_recording_support.work_cycle_recording)."""
    return work_cycle_recording(server, tmp_path_factory)


def test_start_and_stop_describe_the_recording(recorded):
    started, info = recorded.started, recorded.info
    assert started.active and started.name == NAME and not info.active and info.name == NAME
    assert started.scene_id == info.scene_id and Path(info.path).name == NAME
    assert Path(info.ros2_path) == Path(info.path).with_name("work-cycle.ros2"), info.ros2_path
    assert recorded.local.read_bytes() == Path(info.path).read_bytes(), "the download is the file"
    assert info.frames == recorded.data.frames > 10
    assert (info.start_time, info.end_time) == (recorded.data.times[0], recorded.data.times[-1])
    assert info.end_time >= recorded.result.time[-1] - 1e-9, "the recording covers the whole cycle"
    assert info.bytes == Path(info.path).stat().st_size, "Recording.bytes: the file's size (recording.proto)"


def test_file_opens_with_the_mcap_reader_and_every_message_decodes_with_its_embedded_schema(recorded):
    """make_reader seeks (summary, chunk indexes present); every message of every channel decodes with a class
    built from the file's own schema and leaves no unknown field; graspsim's channels equal this client's classes."""
    with open(recorded.local, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        assert isinstance(reader, SeekingReader)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None and summary.chunk_indexes, "summary + index"
        assert {c.compression for c in summary.chunk_indexes} == {"zstd"}
        channels = {c.topic: c for c in summary.channels.values()}
        required = set(SCHEMAS) - {"/log"}  # /log: present when anything was logged
        assert required <= set(channels), sorted(required - set(channels))
        for topic, channel in channels.items():
            schema = summary.schemas[channel.schema_id]
            assert (channel.message_encoding, schema.encoding) == ("protobuf", "protobuf"), topic
            if topic in SCHEMAS:
                assert schema.name == SCHEMAS[topic], (topic, schema.name)
        counts = Counter()
        for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=False):
            counts[channel.topic] += 1
            assert len(UnknownFieldSet(decoded)) == 0, f"{channel.topic}: fields the schema lacks"
            own = OWN_CLASSES.get(channel.topic)
            if own is not None:
                assert own.FromString(message.data).SerializeToString(deterministic=True) == \
                    decoded.SerializeToString(deterministic=True), channel.topic
        assert sum(counts.values()) == summary.statistics.message_count == recorded.info.messages
        assert counts == Counter(recorded.per_topic)
    frames = recorded.data.frames
    assert frames > 10
    for topic in ("/graspsim/snapshot", "/graspsim/state", "/tf", *(f"/tactile/{pad}" for pad in PADS)):
        assert counts[topic] == frames, f"{topic}: {counts[topic]} messages for {frames} frames"
    assert counts["/graspsim/sensor"] == frames * (len(PADS) + 1), "one per pad and per F/T joint per frame"
    assert recorded.data.states == frames
    assert np.all(np.diff(recorded.data.times) >= 0)


def test_edits_and_scene_come_first(recorded):
    """"/graspsim/edit" holds the scene's edits in order, before the first frame, as their journal records;
    "/graspsim/scene" is GetScene with geometry (bodies, joints, robots, tactile arrays) and its body list does not
    change during the cycle, so it is there once."""
    with open(recorded.local, "rb") as f:
        reader = make_reader(f)
        edits = [(m.log_time, recording_pb2.RecordedEdit.FromString(m.data))
                 for _, _, m in reader.iter_messages(topics=["/graspsim/edit"], log_time_order=False)]
        scenes = [(m.log_time, scene_pb2.Scene.FromString(m.data))
                  for _, _, m in reader.iter_messages(topics=["/graspsim/scene"], log_time_order=False)]
    assert len(scenes) == 1 and scenes[0][0] <= recorded.data.log_times[0]
    # The recorded message read as get_scene's reply: the dataclasses compare every value, arrays included.
    before, recorded_scene = recorded.scene_before, graspsim.Scene.from_proto(scenes[0][1])
    for field in ("bodies", "robots", "tactile_arrays"):
        assert getattr(recorded_scene, field) == getattr(before, field), field
    assert [j.id for j in recorded_scene.joints] == [j.id for j in before.joints]
    assert all(b.collision for b in recorded_scene.bodies if b.id in ("table", "cube")), "with their shapes"
    assert [e.kind for _, e in edits] == ["AddObject", "AddObject", "AddRobot"], [e.kind for _, e in edits]
    assert max(t for t, _ in edits) <= recorded.data.log_times[0]
    # Each edit is its journal record: "GSEDIT", format version 2, then its fields by name in CBOR.
    assert all(e.request.startswith(b"GSEDIT\x02") for _, e in edits)
    records = [cbor2.loads(e.request[7:]) for _, e in edits]
    assert [r["name"] for r in records] == ["table", "cube", "cell"]
    assert records[2]["format"] == "builtin" and records[2]["source"] == "schunk_pg70_on_z_axis"
    assert records[1]["builtin"] == "cube_5cm"


def test_foxglove_channels_decode_with_foxglove_classes_and_match_the_snapshots(recorded):
    """Foxglove's own generated classes read /tf, /scene, /tactile/*, /log; every transform equals the
    /graspsim/snapshot pose of its body at the same time (1e-12), the tactile images equal the recorded
    intensities and read pressure throughout the hold."""
    data = recorded.data
    frame_of = {key: i for i, key in enumerate(keyed(data.log_times))}
    column = {b: j for j, b in enumerate(data.body_ids)}
    messages = defaultdict(list)
    with open(recorded.local, "rb") as f:
        for _, channel, m in make_reader(f).iter_messages(topics=list(FOXGLOVE_CLASSES), log_time_order=False):
            decoded = FOXGLOVE_CLASSES[channel.topic].FromString(m.data)
            assert len(UnknownFieldSet(decoded)) == 0, channel.topic
            messages[channel.topic].append((m.log_time, decoded))

    transforms = messages["/tf"]
    assert len(transforms) == data.frames
    for key, (log_time, tf) in zip(keyed(t for t, _ in transforms), transforms):
        i = frame_of[key]
        present = [b for b in data.body_ids if not np.isnan(data.body_poses[i, column[b], 0])]
        assert sorted(t.child_frame_id for t in tf.transforms) == sorted(present), "every body, once"
        for t in tf.transforms:
            assert t.parent_frame_id == "world" and stamp_ns(t.timestamp) == log_time
            got = [t.translation.x, t.translation.y, t.translation.z,
                   t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z]
            np.testing.assert_allclose(got, data.body_poses[i, column[t.child_frame_id]], **EXACT,
                                       err_msg=f"/tf {t.child_frame_id} at frame {i}")

    scenes = messages["/scene"]
    assert scenes and scenes[0][0] <= data.log_times[0], "the 3D scene is there from the start"
    for _, update in scenes:
        ids = [e.frame_id for e in update.entities]
        assert len(ids) == len(set(ids)) and set(ids) == set(data.body_ids), "one entity per body"
    drawn = [e for _, update in scenes[:1] for e in update.entities
             if e.cubes or e.spheres or e.cylinders or e.triangles or e.models]
    assert {e.frame_id for e in drawn} >= {"table", "cube"}, "the objects have shapes to draw"

    # While the cube is carried (lift and hold) both pads press on it.
    spans = {name: (start, end) for name, start, end in recorded.result.stage_spans()}
    held = (data.times >= spans["lift"][0]) & (data.times <= spans["hold"][1])
    assert held.sum() >= 3, f"frames recorded while the cube is carried: {data.times}"
    for pad in PADS:
        images = messages[f"/tactile/{pad}"]
        readings = recorded.sensors[pad]
        assert len(images) == len(readings) == data.frames
        for (log_time, image), (reading_time, reading) in zip(images, readings):
            assert log_time == reading_time
            t = reading.tactile
            assert (image.encoding, image.width, image.height, image.step) == ("mono16", t.cols, t.rows, 2 * t.cols)
            assert stamp_ns(image.timestamp) == log_time
            np.testing.assert_array_equal(np.frombuffer(image.data, "<u2"), np.frombuffer(t.intensities, "<u2"))
        sums = np.array([np.frombuffer(image.data, "<u2").astype(np.int64).sum() for _, image in images])
        np.testing.assert_array_equal(sums, data.tactile_sums()[pad])
        assert (sums[held] > 0).all(), f"{pad} reads nothing while carrying: {sums[held]}"
        assert sums[-1] == 0, "released at the end"
    for _, log in messages.get("/log", []):
        assert log.message


def test_ros2_bag_reads_with_rosbags_and_matches_the_snapshots(recorded):
    """The ROS 2 bag beside the file: rosbags opens it, every message deserializes both with ROS 2 Humble's
    definitions and with those the bag embeds; TF equals the recorded poses, JointState the recorded joints,
    the requested F/T joint has its WrenchStamped, the pads their normal forces."""
    data = recorded.data
    bag = Path(recorded.info.ros2_path)
    assert bag.is_dir() and (bag / "metadata.yaml").is_file() and len(list(bag.glob("*.mcap"))) == 1
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    messages = defaultdict(list)
    with Ros2Reader(bag) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        assert types == ROS2_TYPES, types
        for connection, timestamp, raw in reader.messages():
            messages[connection.topic].append((timestamp, typestore.deserialize_cdr(raw, connection.msgtype)))
        assert reader.message_count == sum(len(m) for m in messages.values())
    with AnyReader([bag]) as reader:  # the bag's own message definitions (ros2msg schemas)
        count = 0
        for connection, _, raw in reader.messages():
            reader.deserialize(raw, connection.msgtype)
            count += 1
    assert count == sum(len(m) for m in messages.values())

    frame_of = {key: i for i, key in enumerate(keyed(data.log_times))}
    column = {b: j for j, b in enumerate(data.body_ids)}
    tf = messages["/tf"]
    assert len(tf) == data.frames
    for key, (timestamp, message) in zip(keyed(t for t, _ in tf), tf):
        i = frame_of[key]
        assert sorted(t.child_frame_id for t in message.transforms) == sorted(data.body_ids)
        for t in message.transforms:
            assert t.header.frame_id == "world" and stamp_ns(t.header.stamp) == timestamp
            tr, q = t.transform.translation, t.transform.rotation
            np.testing.assert_allclose([tr.x, tr.y, tr.z, q.w, q.x, q.y, q.z],
                                       data.body_poses[i, column[t.child_frame_id]], rtol=0, atol=1e-9)

    # JointState lists the joints that move (ROS: fixed joints are robot_state_publisher's), in the snapshot's order.
    with open(recorded.local, "rb") as f:
        _, _, first_scene = next(make_reader(f).iter_messages(topics=["/graspsim/scene"]))
    fixed = {j.id for j in scene_pb2.Scene.FromString(first_scene.data).joints
             if j.type == common_pb2.JOINT_TYPE_FIXED}
    assert fixed, "the cell has fixed joints"
    moving = [j for j in data.joint_ids if j not in fixed]
    columns = [data.joint_ids.index(j) for j in moving]
    joints = messages["/joint_states"]
    assert len(joints) == data.frames
    for key, (timestamp, message) in zip(keyed(t for t, _ in joints), joints):
        i = frame_of[key]
        assert list(message.name) == moving and stamp_ns(message.header.stamp) == timestamp
        np.testing.assert_allclose(message.position, data.joint_positions[i, columns], **EXACT)
        assert len(message.velocity) == len(moving)

    wrenches = messages[f"/wrench/{FT_JOINT}"]
    readings = recorded.sensors[FT_JOINT]
    assert len(wrenches) == len(readings) == data.frames
    for (timestamp, message), (log_time, reading) in zip(wrenches, readings):
        assert stamp_ns(message.header.stamp) == timestamp == log_time
        f, m = message.wrench.force, message.wrench.torque
        ft = reading.force_torque
        np.testing.assert_allclose([f.x, f.y, f.z, m.x, m.y, m.z],
                                   [ft.force.x, ft.force.y, ft.force.z, ft.torque.x, ft.torque.y, ft.torque.z],
                                   **EXACT)
    assert np.abs(data.force_torque[FT_JOINT]).max() > 0, "the finger joint transmits a force"

    for pad in PADS:
        arrays = messages[f"/tactile/{pad}"]
        readings = recorded.sensors[pad]
        assert len(arrays) == len(readings) == data.frames
        for (_, message), (_, reading) in zip(arrays, readings):
            t = reading.tactile
            assert [d.size for d in message.layout.dim] == [t.rows, t.cols]
            normal = np.abs(np.frombuffer(t.forces, "<f4").reshape(-1, 3)[:, 2])
            np.testing.assert_allclose(np.abs(message.data), normal, rtol=1e-6, atol=1e-7,
                                       err_msg=f"{pad}: normal forces (N) of the texels")


def test_list_and_download_while_recording(client, scene_id, tmp_path):
    """An active recording is listed first and downloads as far as written (a truncated file that reads);
    the default name is "<scene id>-<UTC time>.mcap"; after the stop the file is whole."""
    client.add_object(scene_id, "box", box=(0.05, 0.05, 0.05), mass=0.1, pose=[0, 0, 1, 1, 0, 0, 0])
    info = client.start_recording(scene_id, groups=["graspsim"], compression="lz4")
    assert info.active and info.name.startswith(f"{scene_id}-") and info.name.endswith(".mcap")
    assert info.ros2_path == "", "no ROS 2 bag without the ros2 group"
    try:
        client.step_simulation(scene_id, duration=0.5)
        deadline = time.monotonic() + 10
        while True:  # the server's writer takes the frames on a thread of its own
            listed = client.list_recordings()
            ours = next(r for r in listed if r.name == info.name)
            if ours.frames >= 2 or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        flags = [r.active for r in listed]
        assert flags == sorted(flags, reverse=True), "active recordings first"
        assert ours.active and ours.frames >= 2 and ours.scene_id == scene_id
        partial = client.download_recording(info.name, tmp_path / "partial.mcap")
        assert graspsim.mcap.read(partial).truncated, "an active recording has no footer yet"
    finally:
        stopped = client.stop_recording(scene_id)
    assert not stopped.active and stopped.frames >= ours.frames
    whole = graspsim.mcap.read(client.download_recording(stopped.name, tmp_path / "whole.mcap"))
    written = partial.read_bytes()
    assert (tmp_path / "whole.mcap").read_bytes()[:len(written)] == written, "what was written stays as it was"
    assert not whole.truncated and whole.frames == stopped.frames and whole.body_ids == ["box"]
    assert (whole.times[0], whole.times[-1]) == (stopped.start_time, stopped.end_time)
    assert set(whole.messages_per_topic) <= set(OWN_CLASSES), "only the graspsim group"
    with open(tmp_path / "whole.mcap", "rb") as f:
        assert {c.compression for c in make_reader(f).get_summary().chunk_indexes} == {"lz4"}
    listed = {r.name: r for r in client.list_recordings()}
    assert not listed[stopped.name].active and listed[stopped.name].bytes == stopped.bytes


def test_bad_requests_name_the_field_and_write_nothing_outside(start_server, tmp_path):
    """Names that would leave the recording directory are refused (INVALID_ARGUMENT naming `name`), an unknown
    scene is NOT_FOUND, a second recording of a scene ALREADY_EXISTS; no file appears outside the directory."""
    recordings = tmp_path / "inside" / "recordings"
    outside_before = {p for p in ("/etc/x", "/etc/x.mcap", "/x.mcap") if os.path.exists(p)}
    proc = start_server(f"--recording-dir={recordings}")
    with graspsim.connect(proc.address) as client:
        scene = client.create_scene("bad input")
        client.add_object(scene.id, "box", box=(0.05, 0.05, 0.05), mass=0.1, pose=[0, 0, 1, 1, 0, 0, 0])
        for bad in ("../x.mcap", "/etc/x", "/etc/x.mcap", "sub/x.mcap", "..", "x.txt", "../../../x.mcap",
                    "a b.mcap", ".mcap/../x.mcap"):
            with expect_error(IA, "name"):
                client.start_recording(scene, name=bad)
        assert client.list_recordings() == [], "a refused start records nothing"
        with expect_error(IA, "groups", "bogus"):
            client.start_recording(scene, name="g.mcap", groups=["bogus"])
        with expect_error(IA, "compression", "gzip"):
            client.start_recording(scene, name="c.mcap", compression="gzip")
        with pytest.raises(graspsim.GraspsimError) as info:
            client.start_recording(scene, name="j.mcap", force_torque_joints=["no/such_joint"])
        assert info.value.code in (IA, NOT_FOUND) and "no/such_joint" in info.value.message, info.value
        with expect_error(NOT_FOUND, "scene_id"):
            client.start_recording("no-such-scene", name="y.mcap")
        with pytest.raises(graspsim.GraspsimError) as info:
            client.stop_recording(scene)  # nothing to stop
        assert info.value.code in (NOT_FOUND, grpc.StatusCode.FAILED_PRECONDITION), info.value
        assert client.list_recordings() == []

        client.start_recording(scene, name="ok.mcap")
        with expect_error(grpc.StatusCode.ALREADY_EXISTS):
            client.start_recording(scene, name="other.mcap")
        client.step_simulation(scene.id, duration=0.1)
        stopped = client.stop_recording(scene)
        assert stopped.frames > 0 and Path(stopped.path) == recordings / "ok.mcap"

        for bad in ("../x.mcap", "/etc/passwd", "../inside/recordings/ok.mcap"):
            with expect_error(IA, "name"):
                client.download_recording(bad, tmp_path / "download.mcap")
            with expect_error(IA, "name"):
                client.replay_recording(bad)
        with expect_error(NOT_FOUND, "missing.mcap"):
            client.download_recording("missing.mcap", tmp_path / "download.mcap")
        assert not (tmp_path / "download.mcap").exists() and not list(tmp_path.glob(".download.mcap.*")), \
            "a failed download leaves no file"
        with expect_error(NOT_FOUND, "missing.mcap"):
            client.replay_recording("missing.mcap")
        replay = client.replay_recording("ok.mcap")
        with pytest.raises(graspsim.GraspsimError) as info:
            client.seek_replay(replay, "ok.mcap", replay.frames)
        assert info.value.code in (IA, grpc.StatusCode.OUT_OF_RANGE) and "frame" in info.value.message, info.value
        with expect_error(NOT_FOUND, "scene_id"):
            client.seek_replay("no-such-scene", "ok.mcap", 0)
        names = [r.name for r in client.list_recordings()]
        assert names == ["ok.mcap"], names
    outside = [p for p in tmp_path.rglob("*.mcap") if recordings.resolve() not in p.resolve().parents]
    assert outside == [], outside
    assert (recordings / "ok.mcap").is_file()
    assert {p for p in ("/etc/x", "/etc/x.mcap", "/x.mcap") if os.path.exists(p)} == outside_before

