"""Shared pieces of the recording tests (test_recording*.py, issue 25, docs/recording.md): the work-cycle cell and
its recording (made once per server and shared by the modules), the channels a recording has, frames paired across
channels, files written with mcap's own writer, and replays sought frame by frame against recorded snapshots.

Frames pair up across channels by their MCAP log_time (simulation time, ns): the k-th message of a time on one
channel belongs with the k-th of that time on another (graspsim.mcap does the same).
"""
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Dict

import grpc
import numpy as np
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.Log_pb2 import Log
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from google.protobuf.descriptor_pb2 import FileDescriptorSet
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

import graspsim
import graspsim.mcap
from graspsim.v1 import recording_pb2, scene_pb2, tactile_pb2

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


_WORK_CYCLES: Dict[str, Recorded] = {}  # by server address


def work_cycle_recording(server, tmp_path_factory) -> Recorded:
    """One work cycle recorded on the shared server (StartRecording -> RunWorkCycle -> StopRecording through
    Client.record), downloaded; the live scene's end state kept for the replay test. Made once per server and
    shared by every module that asks (the cycle is the slow part), so the modules only read it."""
    if server.address in _WORK_CYCLES:
        return _WORK_CYCLES[server.address]
    local = tmp_path_factory.mktemp("recording") / NAME
    with graspsim.connect(server.address) as client:
        scene = client.create_scene("test_recording")
        try:
            build_cell(client, scene.id)
            scene_before = client.get_scene(scene.id, include_geometry=True)
            with client.record(scene, local, name=NAME, force_torque_joints=[FT_JOINT]) as info:
                started = graspsim.RecordingInfo(**vars(info))
                result = client.run_work_cycle(scene.id, "cell", "cube", lift_height=LIFT, hold_time=HOLD,
                                               tactile_setpoint=SETPOINT, timeout=300)
            final_poses = client.get_body_poses(scene.id)
            final_joints = client.get_joint_positions(scene.id)
        finally:
            client.delete_scene(scene.id)  # the recording is the file now; replays build scenes of their own
    sensors = defaultdict(list)
    per_topic = Counter()
    with open(local, "rb") as f:
        for _, channel, message in make_reader(f).iter_messages(log_time_order=False):
            per_topic[channel.topic] += 1
            if channel.topic == "/graspsim/sensor":
                reading = tactile_pb2.SensorReading.FromString(message.data)
                sensors[reading.sensor_id].append((message.log_time, reading))
    recorded = Recorded(info=info, started=started, local=local, data=graspsim.mcap.read(local), result=result,
                        final_poses=final_poses, final_joints=final_joints, scene_before=scene_before,
                        sensors=dict(sensors), per_topic=dict(per_topic))
    _WORK_CYCLES[server.address] = recorded
    return recorded


def assert_replay_matches_snapshots(client, replay, data, frames=None):
    """SeekReplay to each of the first `frames` frames (all: None) in order: the replayed scene has the bodies the
    recorded /graspsim/snapshot of that frame has, at its poses (1e-12). Returns the last frame's poses."""
    poses = {}
    for i in range(replay.frames if frames is None else frames):
        client.seek_replay(replay, replay.name, i)
        poses = client.get_body_poses(replay.scene_id)
        present = [b for j, b in enumerate(data.body_ids) if not np.isnan(data.body_poses[i, j, 0])]
        assert sorted(poses) == sorted(present), f"frame {i}: bodies {sorted(poses)}, recorded {present}"
        for j, body in enumerate(data.body_ids):
            if body in poses:
                np.testing.assert_allclose(poses[body].as_array(), data.body_poses[i, j], **EXACT,
                                           err_msg=f"{body} at frame {i}")
    return poses


def descriptor_set(cls) -> bytes:
    """The protobuf schema of a channel: cls's file and every file it imports, dependencies first."""
    files, out = {}, FileDescriptorSet()

    def add(fd):
        if fd.name not in files:
            for dependency in fd.dependencies:
                add(dependency)
            files[fd.name] = fd
            fd.CopyToProto(out.file.add())
    add(cls.DESCRIPTOR.file)
    return out.SerializeToString()


def write_synthetic(path: Path, frames: int, offset=(0.0, 0.0, 0.0), turn: float = 0.0, extra: int = 0) -> None:
    """A recording of two bodies ("a" falls 1 cm a frame, "b" turns about z by `turn` rad) and one 2 x 3 pad whose
    texels read the frame index + extra, written with mcap.writer (zstd chunks of 2 kB: many chunks)."""
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


def rewrite_with_mcap_writer(source: Path, target: Path, compression: CompressionType, chunk_size: int) -> int:
    """Every message of `source`, in file order, written again to `target` by mcap's own Writer: the same schemas
    (name, encoding, bytes), channels (topic, encoding, metadata) and messages (times, sequence, bytes), each schema
    and channel registered just before its first message, as the server does. Returns the messages written."""
    written = 0
    with open(source, "rb") as f, open(target, "wb") as out:
        reader = make_reader(f)
        writer = Writer(out, compression=compression, chunk_size=chunk_size)
        writer.start(reader.get_header().profile, "graspsim tests (mcap.writer)")
        schemas, channels = {0: 0}, {}
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            if channel.id not in channels:
                if schema is not None and schema.id not in schemas:
                    schemas[schema.id] = writer.register_schema(schema.name, schema.encoding, schema.data)
                channels[channel.id] = writer.register_channel(channel.topic, channel.message_encoding,
                                                               schemas[channel.schema_id], dict(channel.metadata))
            writer.add_message(channels[channel.id], message.log_time, message.data, message.publish_time,
                               message.sequence)
            written += 1
        writer.finish()
    return written
