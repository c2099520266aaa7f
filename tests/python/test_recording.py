"""RecordingService through the real server (issue 25, docs/recording.md): a work cycle recorded as MCAP and
checked with the field's own readers, not only ours: mcap's seeking and streaming readers, classes built from the
schemas embedded in the file (mcap-protobuf-support), Foxglove's generated classes (foxglove-schemas-protobuf),
rosbags for the ROS 2 bag, and @mcap/core + protobufjs + @foxglove/ws-protocol in Node (tests/node, installed by
`make node-tests`). A recording cut by kill -9 reads up to the cut; a replay seeks to every recorded state.

Frames pair up across channels by their MCAP log_time (simulation time, ns): the k-th message of a time on one
channel belongs with the k-th of that time on another (graspsim.mcap does the same).
"""
import json
import os
import shutil
import signal
import subprocess
import threading
import time
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Dict

import grpc
import numpy as np
import pytest
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.Log_pb2 import Log
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from google.protobuf.unknown_fields import UnknownFieldSet
from mcap.reader import SeekingReader, make_reader
from mcap.stream_reader import StreamReader
from mcap_protobuf.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import Reader as Ros2Reader
from rosbags.typesys import Stores, get_typestore

import graspsim
import graspsim.mcap
from graspsim.v1 import common_pb2, recording_pb2, scene_pb2, tactile_pb2

from _support import IA, expect_error
from conftest import REPO_ROOT, ServerProcess, free_port

TABLE_TOP = 0.75   # m, built-in table (as tests/python/test_work_cycle.py)
CUBE = 0.05        # m, built-in cube_5cm edge
BASE_Z = 1.05      # m, the cell's axis base
LIFT = 0.03        # m
HOLD = 0.3         # s
SETPOINT = 60000.0
FT_JOINT = "cell/finger_left_joint"
PADS = ("cell/pad_left", "cell/pad_right")
NAME = "work-cycle.mcap"

NOT_FOUND = grpc.StatusCode.NOT_FOUND
EXACT = dict(rtol=0, atol=1e-12)  # what "bit for bit through float64" leaves room for

# Every channel of a recording with all three groups: topic -> schema name (protobuf, the FileDescriptorSet).
OWN_CLASSES = {"/graspsim/edit": recording_pb2.RecordedEdit, "/graspsim/scene": scene_pb2.Scene,
               "/graspsim/snapshot": scene_pb2.SceneSnapshot, "/graspsim/state": recording_pb2.RecordedState,
               "/graspsim/sensor": tactile_pb2.SensorReading}
FOXGLOVE_CLASSES = {"/tf": FrameTransforms, "/scene": SceneUpdate, "/log": Log,
                    **{f"/tactile/{pad}": RawImage for pad in PADS}}
SCHEMAS = {**{topic: cls.DESCRIPTOR.full_name for topic, cls in OWN_CLASSES.items()},
           **{topic: cls.DESCRIPTOR.full_name for topic, cls in FOXGLOVE_CLASSES.items()}}
ROS2_TYPES = {"/tf": "tf2_msgs/msg/TFMessage", "/joint_states": "sensor_msgs/msg/JointState",
              **{f"/tactile/{pad}": "std_msgs/msg/Float32MultiArray" for pad in PADS},
              f"/wrench/{FT_JOINT}": "geometry_msgs/msg/WrenchStamped"}


def build_cell(client, scene_id: str) -> None:
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
    client.add_robot(scene_id, "cell", builtin="schunk_pg70_on_z_axis", base_pose=[0, 0, BASE_Z, 1, 0, 0, 0])


def keyed(log_times):
    """(log_time, k) of each message: the k-th at that log time."""
    seen = Counter()
    keys = []
    for t in log_times:
        keys.append((int(t), seen[t]))
        seen[t] += 1
    return keys


def stamp_ns(stamp) -> int:
    """A ROS builtin_interfaces/Time or a google.protobuf.Timestamp as ns."""
    if hasattr(stamp, "nanosec"):
        return stamp.sec * 1_000_000_000 + stamp.nanosec
    return stamp.seconds * 1_000_000_000 + stamp.nanos


@dataclass
class Recorded:
    info: graspsim.RecordingInfo   # after StopRecording
    started: graspsim.RecordingInfo
    local: Path                    # the downloaded .mcap
    data: graspsim.mcap.RecordingData
    result: object                 # the WorkCycleResult
    final_poses: Dict[str, graspsim.Pose]
    final_joints: Dict[str, float]
    scene_before: object           # GetScene with geometry just before the recording started
    sensors: Dict[str, list]       # /graspsim/sensor readings by sensor id, in file order: (log_time, SensorReading)
    per_topic: Dict[str, int]


@pytest.fixture(scope="module")
def recorded(server, tmp_path_factory):
    """One work cycle recorded on the shared server (StartRecording -> RunWorkCycle -> StopRecording through
    Client.record), downloaded; the live scene's end state kept for the replay test."""
    local = tmp_path_factory.mktemp("recording") / NAME
    with graspsim.connect(server.address) as client:
        scene = client.create_scene("test_recording")
        build_cell(client, scene.id)
        scene_before = client.get_scene(scene.id, include_geometry=True)
        with client.record(scene, local, name=NAME, force_torque_joints=[FT_JOINT]) as info:
            started = graspsim.RecordingInfo(**vars(info))
            result = client.run_work_cycle(scene.id, "cell", "cube", lift_height=LIFT, hold_time=HOLD,
                                           tactile_setpoint=SETPOINT, timeout=300)
        final_poses = client.get_body_poses(scene.id)
        final_joints = client.get_joint_positions(scene.id)
        sensors = defaultdict(list)
        per_topic = Counter()
        with open(local, "rb") as f:
            for _, channel, message in make_reader(f).iter_messages(log_time_order=False):
                per_topic[channel.topic] += 1
                if channel.topic == "/graspsim/sensor":
                    reading = tactile_pb2.SensorReading.FromString(message.data)
                    sensors[reading.sensor_id].append((message.log_time, reading))
        yield Recorded(info=info, started=started, local=local, data=graspsim.mcap.read(local), result=result,
                       final_poses=final_poses, final_joints=final_joints, scene_before=scene_before,
                       sensors=dict(sensors), per_topic=dict(per_topic))
        client.delete_scene(scene.id)


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
    """"/graspsim/edit" holds the scene's edits in order, before the first frame, as their request messages;
    "/graspsim/scene" is GetScene with geometry (bodies, joints, robots, tactile arrays) and its body list does not
    change during the cycle, so it is there once."""
    with open(recorded.local, "rb") as f:
        reader = make_reader(f)
        edits = [(m.log_time, recording_pb2.RecordedEdit.FromString(m.data))
                 for _, _, m in reader.iter_messages(topics=["/graspsim/edit"], log_time_order=False)]
        scenes = [(m.log_time, scene_pb2.Scene.FromString(m.data))
                  for _, _, m in reader.iter_messages(topics=["/graspsim/scene"], log_time_order=False)]
    assert len(scenes) == 1 and scenes[0][0] <= recorded.data.log_times[0]
    before, recorded_scene = recorded.scene_before, scenes[0][1]
    for field in ("bodies", "robots", "tactile_arrays"):
        assert [m.SerializeToString(deterministic=True) for m in getattr(recorded_scene, field)] == \
            [m.SerializeToString(deterministic=True) for m in getattr(before, field)], field
    assert [j.id for j in recorded_scene.joints] == [j.id for j in before.joints]
    assert all(b.collision for b in recorded_scene.bodies if b.id in ("table", "cube")), "with their shapes"
    assert [e.kind for _, e in edits] == ["AddObject", "AddObject", "AddRobot"], [e.kind for _, e in edits]
    assert max(t for t, _ in edits) <= recorded.data.log_times[0]
    names = [scene_pb2.AddObjectRequest.FromString(edits[0][1].request).name,
             scene_pb2.AddObjectRequest.FromString(edits[1][1].request).name,
             scene_pb2.AddRobotRequest.FromString(edits[2][1].request).name]
    assert names == ["table", "cube", "cell"]
    assert scene_pb2.AddRobotRequest.FromString(edits[2][1].request).builtin == "schunk_pg70_on_z_axis"


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


def test_a_recording_cut_by_kill_9_reads_up_to_the_cut(tmp_path):
    """kill -9 in the middle of a long StepSimulation run: the file stops inside a record, without summary.
    graspsim.mcap.read keeps every complete frame; mcap's own StreamReader reads every record before the cut
    without error. (A ServerProcess of the test's own: the start_server fixture expects exit code 0.)"""
    recordings = tmp_path / "recordings"
    proc = ServerProcess([f"--recording-dir={recordings}"], tmp_path)
    stepping_error = []
    try:
        with graspsim.connect(proc.address) as client:
            scene_id = client.create_scene("killed").id
            client.add_object(scene_id, "ground", box=(3, 3, 0.1), is_static=True, pose=[0, 0, -0.05, 1, 0, 0, 0])
            for i in range(12):
                client.add_object(scene_id, f"box{i}", box=(0.05, 0.05, 0.05), mass=0.1,
                                  pose=[0.2 * (i % 4) - 0.3, 0.2 * (i // 4) - 0.2, 0.3 + 0.05 * i, 1, 0, 0, 0])
            info = client.start_recording(scene_id, name="killed.mcap")
            path = Path(info.path)
            assert path.parent == recordings

            def step():
                try:
                    while True:
                        client.step_simulation(scene_id, duration=0.5)
                except graspsim.GraspsimError as err:
                    stepping_error.append(err)

            thread = threading.Thread(target=step, daemon=True)
            thread.start()
            deadline = time.monotonic() + 120
            frames = 0
            while time.monotonic() < deadline and frames < 20:
                time.sleep(0.2)
                frames = graspsim.mcap.read(path).frames if path.exists() else 0
            assert frames >= 20, f"no 20 frames on disk within 120 s ({frames})"
            assert thread.is_alive(), f"the run ended before the kill: {stepping_error}"
            os.kill(proc.process.pid, signal.SIGKILL)
            proc.process.wait(timeout=30)
            thread.join(timeout=60)
    finally:
        if proc.process.poll() is None:
            proc.process.kill()
            proc.process.wait()
    assert proc.process.returncode == -signal.SIGKILL
    assert stepping_error and stepping_error[0].code == grpc.StatusCode.UNAVAILABLE, stepping_error

    data = graspsim.mcap.read(path)
    assert data.truncated and data.frames >= frames
    assert data.body_ids[:1] == ["ground"] and len(data.body_ids) == 13
    assert np.isfinite(data.body_poses).all() and np.all(np.diff(data.times) >= 0)
    assert data.frames - 1 <= data.messages_per_topic["/tf"] <= data.frames, "the cut may fall inside a frame"

    end, truncated = graspsim.mcap.complete_prefix(path)
    size = path.stat().st_size
    assert truncated and 8 < end <= size
    bounded = [r for r in graspsim.mcap.iter_records(path)]  # stops at the cut by itself
    raw = []
    with open(path, "rb") as f:
        try:
            for record in StreamReader(f, validate_crcs=True).records:
                raw.append(record)
        except Exception:  # noqa: BLE001 — the cut: EndOfFile or the incomplete last chunk
            pass
        else:
            pytest.fail("the stream reader found a complete file after kill -9")
        assert f.tell() > end or end == size, "the reader failed before the last complete record"
    assert [type(r).__name__ for r in raw] == [type(r).__name__ for r in bounded][:len(raw)]
    assert len(raw) == len(bounded), "every complete record before the cut reads with mcap's StreamReader"
    assert sum(type(r).__name__ == "Message" for r in raw) == sum(data.messages_per_topic.values())


def test_replay_seeks_to_every_recorded_frame(client, recorded):
    """ReplayRecording rebuilds the scene; SeekReplay to every 10th frame and the last puts every body where the
    /graspsim/snapshot says (1e-12); the last frame is where the live scene ended after the cycle."""
    data = recorded.data
    replay = client.replay_recording(recorded.info.name, scene_name="test_recording replay")
    try:
        assert isinstance(replay, graspsim.Replay) and replay.frames == data.frames
        np.testing.assert_array_equal(replay.frame_times, data.times)
        assert {s.id: s.name for s in client.list_scenes()}[replay.scene_id] == "test_recording replay"
        column = {b: j for j, b in enumerate(data.body_ids)}
        revisions = []
        for i in sorted(set(range(0, data.frames, 10)) | {data.frames - 1}):
            t, revision = client.seek_replay(replay, recorded.info.name, i)
            assert t == data.times[i]
            revisions.append(revision)
            poses = client.get_body_poses(replay.scene_id)
            assert set(poses) == set(data.body_ids)
            for body, pose in poses.items():
                np.testing.assert_allclose(pose.as_array(), data.body_poses[i, column[body]], **EXACT,
                                           err_msg=f"{body} at frame {i}")
            joints = client.get_joint_positions(replay.scene_id)
            np.testing.assert_allclose([joints[j] for j in data.joint_ids], data.joint_positions[i], **EXACT)
        assert revisions == sorted(revisions) and len(set(revisions)) == len(revisions), "each seek is an edit"
        assert set(poses) == set(recorded.final_poses)
        for body, pose in recorded.final_poses.items():
            np.testing.assert_allclose(poses[body].as_array(), pose.as_array(), **EXACT,
                                       err_msg=f"{body}: the last frame is the live scene's end")
        np.testing.assert_allclose([joints[j] for j in data.joint_ids],
                                   [recorded.final_joints[j] for j in data.joint_ids], **EXACT)
    finally:
        client.delete_scene(replay.scene_id)


def test_compare_is_zero_for_itself_and_finite_for_a_rerun(client, recorded, tmp_path):
    """graspsim.mcap.compare: a recording against itself is all zeros; against the work cycle run again on its
    replayed scene (sought to the first frame), a finite report over the frames both have."""
    same = graspsim.mcap.compare(recorded.local, recorded.local)
    assert same["frames_compared"] == recorded.data.frames and same["frames_only_in_a"] == 0
    assert same["bodies_compared"] == len(recorded.data.body_ids) and same["sensors_compared"] == len(PADS)
    for key in ("max_position_diff_m", "max_orientation_diff_rad", "max_joint_diff", "max_tactile_sum_diff"):
        assert same[key] == 0, (key, same)

    replay = client.replay_recording(recorded.info.name)
    try:
        assert {s.id: s.name for s in client.list_scenes()}[replay.scene_id] == f"replay of {recorded.info.name}"
        client.seek_replay(replay, recorded.info.name, 0)
        rerun = tmp_path / "rerun.mcap"
        with client.record(replay, rerun, name="rerun.mcap", force_torque_joints=[FT_JOINT]) as info:
            client.run_work_cycle(replay.scene_id, "cell", "cube", lift_height=LIFT, hold_time=HOLD,
                                  tactile_setpoint=SETPOINT, timeout=300)
        assert info.frames > 10 and not info.active, "record() left the stopped figures in its info"
    finally:
        client.delete_scene(replay.scene_id)
    report = graspsim.mcap.compare(recorded.local, rerun)
    # The frames' times depend on how the server chunked the run (wall time), so only some align; the first
    # (the state the replay was sought to) always does.
    assert report["frames_compared"] >= 1 and report["bodies_compared"] == len(recorded.data.body_ids)
    assert report["frames_compared"] + report["frames_only_in_a"] == recorded.data.frames
    for key in ("max_position_diff_m", "max_orientation_diff_rad", "max_joint_diff", "max_tactile_sum_diff"):
        assert np.isfinite(report[key]) and report[key] >= 0, (key, report)
    assert report["max_orientation_diff_rad"] <= np.pi


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


def test_record_flag_records_every_scene_from_its_creation_and_replays_it(start_server, tmp_path):
    """--record DIR: a scene is recorded from its creation, so its edits happen while recording (a body added
    after the first steps); the recording still replays, and every frame seeks to its bodies' poses (1e-12)."""
    directory = tmp_path / "auto"
    proc = start_server(f"--record={directory}")
    with graspsim.connect(proc.address) as client:
        scene = client.create_scene("recorded from its creation")
        client.add_object(scene.id, "box", box=(0.05, 0.05, 0.05), mass=0.1, pose=[0, 0, 1, 1, 0, 0, 0])
        client.step_simulation(scene.id, duration=0.2)
        client.add_object(scene.id, "ball", sphere=0.02, mass=0.1, pose=[0.3, 0, 1, 1, 0, 0, 0])
        client.step_simulation(scene.id, duration=0.2)
        listed = [r for r in client.list_recordings() if r.scene_id == scene.id]
        assert len(listed) == 1 and listed[0].active and Path(listed[0].path).parent == directory, listed
        with expect_error(grpc.StatusCode.ALREADY_EXISTS, "scene_id"):
            client.start_recording(scene)
        stopped = client.stop_recording(scene)
        final = client.get_body_poses(scene.id)
        data = graspsim.mcap.read(stopped.path)
        assert not data.truncated and data.frames == stopped.frames >= 3 and data.body_ids == ["box", "ball"]
        assert np.isnan(data.body_poses[0]).all(), "the scene was empty when it was created"
        assert np.isfinite(data.body_poses[-1]).all()
        assert data.messages_per_topic["/graspsim/scene"] == data.messages_per_topic["/scene"] == 3, \
            "the scene at creation, with the box, with the ball"
        replay = client.replay_recording(stopped.name)
        assert replay.frames == data.frames
        for i in range(data.frames):
            client.seek_replay(replay, stopped.name, i)
            poses = client.get_body_poses(replay.scene_id)
            present = [b for j, b in enumerate(data.body_ids) if not np.isnan(data.body_poses[i, j, 0])]
            assert sorted(poses) == sorted(present), f"frame {i}: bodies {sorted(poses)}, recorded {present}"
            for j, body in enumerate(data.body_ids):
                if body in poses:
                    np.testing.assert_allclose(poses[body].as_array(), data.body_poses[i, j], **EXACT)
        for body, pose in final.items():
            np.testing.assert_allclose(poses[body].as_array(), pose.as_array(), **EXACT)


# --- graspsim.mcap on files written here with mcap's own writer (no server) -----------------------------------
def write_synthetic(path: Path, frames: int, offset=(0.0, 0.0, 0.0), turn: float = 0.0, extra: int = 0) -> None:
    """A recording of two bodies ("a" falls 1 cm a frame, "b" turns about z by `turn` rad) and one 2 x 3 pad whose
    texels read the frame index + extra, written with mcap.writer (zstd chunks of 2 kB: many chunks)."""
    from google.protobuf.descriptor_pb2 import FileDescriptorSet
    from mcap.writer import CompressionType, Writer

    def descriptor_set(cls) -> bytes:
        files, out = {}, FileDescriptorSet()

        def add(fd):
            if fd.name not in files:
                for dependency in fd.dependencies:
                    add(dependency)
                files[fd.name] = fd
                fd.CopyToProto(out.file.add())
        add(cls.DESCRIPTOR.file)
        return out.SerializeToString()

    with open(path, "wb") as f:
        writer = Writer(f, compression=CompressionType.ZSTD, chunk_size=2048)
        writer.start("", "test_recording")
        channels = {}
        for topic, cls in (("/graspsim/snapshot", scene_pb2.SceneSnapshot),
                           ("/graspsim/sensor", tactile_pb2.SensorReading)):
            schema = writer.register_schema(cls.DESCRIPTOR.full_name, "protobuf", descriptor_set(cls))
            channels[topic] = writer.register_channel(topic, "protobuf", schema)
        for i in range(frames):
            t = i * 0.01
            ns = round(t * 1e9)
            c, s_ = np.cos(turn / 2), np.sin(turn / 2)
            poses = np.array([[offset[0], offset[1], 1 - 0.01 * i + offset[2], 1, 0, 0, 0], [1, 0, 0, c, 0, 0, s_]])
            snapshot = scene_pb2.SceneSnapshot(sequence=i, revision=i, time=t, body_ids=["a", "b"],
                                               body_poses=poses.astype("<f8").tobytes(), joint_ids=["j"],
                                               joint_positions=np.array([t], "<f8").tobytes())
            writer.add_message(channels["/graspsim/snapshot"], ns, snapshot.SerializeToString(), ns)
            reading = tactile_pb2.SensorReading(sensor_id="pad", time=t)
            reading.tactile.rows, reading.tactile.cols = 2, 3
            reading.tactile.intensities = np.full(6, i + extra, "<u2").tobytes()
            writer.add_message(channels["/graspsim/sensor"], ns, reading.SerializeToString(), ns)
        writer.finish()


def test_mcap_read_keeps_every_complete_frame_of_a_file_cut_anywhere(tmp_path):
    whole = tmp_path / "whole.mcap"
    write_synthetic(whole, 120)
    data = graspsim.mcap.read(whole)
    assert not data.truncated and data.frames == 120 and data.body_ids == ["a", "b"] and data.joint_ids == ["j"]
    np.testing.assert_array_equal(data.body_poses[:, 0, 2], 1 - 0.01 * np.arange(120))
    np.testing.assert_array_equal(data.tactile["pad"][:, 1, 2], np.arange(120))
    assert data.messages_per_topic == {"/graspsim/snapshot": 120, "/graspsim/sensor": 120}
    raw = whole.read_bytes()
    cut = tmp_path / "cut.mcap"
    previous = 0
    for size in range(8, len(raw), 101):
        cut.write_bytes(raw[:size])
        part = graspsim.mcap.read(cut)
        assert part.truncated and previous <= part.frames <= 120, size
        if part.frames:
            np.testing.assert_array_equal(part.body_poses, data.body_poses[:part.frames])
        np.testing.assert_array_equal(part.tactile.get("pad", np.zeros((0, 2, 3)))[:part.frames - 1],
                                      data.tactile["pad"][:max(part.frames - 1, 0)])
        previous = part.frames
    assert previous == 120, "the messages all precede the summary"
    cut.write_bytes(raw[:len(raw) // 4] + bytes(4096))  # a crash that left zeros after the last write
    assert graspsim.mcap.read(cut).truncated


def test_mcap_compare_reports_known_differences(tmp_path):
    write_synthetic(tmp_path / "a.mcap", 50)
    write_synthetic(tmp_path / "b.mcap", 40, offset=(0.003, 0.004, 0.0), turn=0.25, extra=7)
    same = graspsim.mcap.compare(tmp_path / "a.mcap", tmp_path / "a.mcap")
    assert same["frames_compared"] == 50 and all(same[k] == 0 for k in (
        "max_position_diff_m", "max_orientation_diff_rad", "max_joint_diff", "max_tactile_sum_diff"))
    report = graspsim.mcap.compare(tmp_path / "a.mcap", tmp_path / "b.mcap")
    assert (report["frames_compared"], report["frames_only_in_a"], report["frames_only_in_b"]) == (40, 10, 0)
    assert report["max_position_diff_m"] == pytest.approx(0.005, abs=1e-15)  # the 3-4-5 triangle
    assert report["max_orientation_diff_rad"] == pytest.approx(0.25, abs=1e-12)
    assert report["max_tactile_sum_diff"] == 6 * 7 and report["max_joint_diff"] == 0
    assert report["max_position_diff_body"] == "a"


# --- Node: @mcap/core + protobufjs, and @foxglove/ws-protocol (tests/node, installed by `make node-tests`) ---
NODE = shutil.which("node")
NODE_TESTS = REPO_ROOT / "build" / "node-tests"


def node_script(name: str) -> Path:
    if NODE is None:
        pytest.skip("node is not installed: the JavaScript MCAP and Foxglove readers cannot run")
    script = NODE_TESTS / name
    if not script.is_file() or not (NODE_TESTS / "node_modules").is_dir():
        pytest.fail(f"{script} or its node_modules missing: run `make node-tests`", pytrace=False)
    return script


def test_node_mcap_reader_decodes_every_message(recorded):
    """@mcap/core's indexed reader and protobufjs (from the embedded FileDescriptorSets) read the whole file."""
    run = subprocess.run([NODE, str(node_script("read_mcap.mjs")), str(recorded.local)], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    assert out["decoded_all"] is True, out["undecodable"]
    assert out["per_topic"] == recorded.per_topic
    assert out["messages"] == out["statistics_message_count"] == recorded.info.messages
    assert out["not_protobuf"] == {} and out["reencoded_size_differs"] == {}, out
    assert set(out["compression"]) == {"zstd"}
    first = recorded.data.body_poses[0, :, 0]
    assert sorted(out["first_tf_child_ids"]) == sorted(b for b, x in zip(recorded.data.body_ids, first)
                                                       if not np.isnan(x))


def test_live_foxglove_endpoint_streams_transforms(start_server):
    """--foxglove-listen: Foxglove's own client subscribes to /tf of ws://host:port/<scene id> and receives
    decodable FrameTransforms naming the falling box while the scene steps."""
    script = node_script("foxglove_live.mjs")
    port = free_port()
    proc = start_server(f"--foxglove-listen=127.0.0.1:{port}")
    with graspsim.connect(proc.address) as client:
        scene_id = client.create_scene("live").id
        client.add_object(scene_id, "ground", box=(2, 2, 0.1), is_static=True, pose=[0, 0, -0.05, 1, 0, 0, 0])
        client.add_object(scene_id, "box", box=(0.05, 0.05, 0.05), mass=0.1, pose=[0, 0, 1, 1, 0, 0, 0])
        stop, errors = threading.Event(), []

        def step():
            try:
                while not stop.is_set():
                    client.step_simulation(scene_id, duration=0.02)
                    time.sleep(0.02)
            except graspsim.GraspsimError as err:
                errors.append(err)

        thread = threading.Thread(target=step, daemon=True)
        thread.start()
        try:
            run = subprocess.run([NODE, str(script), f"ws://127.0.0.1:{port}/{scene_id}", "/tf", "5", "30"],
                                 capture_output=True, text=True, timeout=90)
        finally:
            stop.set()
            thread.join(timeout=30)
    assert not errors, errors
    assert run.stdout, run.stderr
    out = json.loads(run.stdout)
    assert run.returncode in (0, 2), (run.returncode, run.stderr, out)
    assert out["subprotocol"] == "foxglove.websocket.v1" and out["schema_name"] == "foxglove.FrameTransforms", out
    assert out["received"] >= 3 and out["decoded"] == out["received"], out
    assert "box" in out["first_child_ids"] and "ground" in out["first_child_ids"], out
