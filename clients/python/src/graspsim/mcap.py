"""graspsim.mcap: a graspsim recording (an .mcap file, docs/recording.md) read into numpy, and two compared.

    import graspsim.mcap
    data = graspsim.mcap.read("run.mcap")
    data.times            # (frames,) s
    data.body_poses       # (frames, bodies, 7): x y z (m), qw qx qy qz, in data.body_ids order
    graspsim.mcap.compare("run.mcap", "rerun.mcap")["max_position_diff_m"]

Needs the `mcap` package (the client's optional extra "record": pip install 'graspsim[record]'); messages are
decoded with this client's own graspsim.v1 classes. Only graspsim's own channels ("/graspsim/snapshot",
"/graspsim/sensor", "/graspsim/state") are read; the Foxglove and ROS 2 channels carry the same data for other tools.

A file whose writer died (server killed mid-recording) has no summary and ends inside a record: read() streams the
file front to back (no seeking), keeps every record that is complete and stops at the first one that is not.
"""
from __future__ import annotations

import io
import os
import struct
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, Dict, Generator, Iterable, List, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

try:
    from mcap.exceptions import EndOfFile
    from mcap.opcode import Opcode
    from mcap.records import Channel, Message
    from mcap.stream_reader import StreamReader
except ImportError as err:  # the optional extra is not installed
    raise ImportError("graspsim.mcap needs the mcap package: pip install 'graspsim[record]'") from err

from graspsim.v1 import recording_pb2, scene_pb2, tactile_pb2

MAGIC = b"\x89MCAP0\r\n"
SNAPSHOT_TOPIC = "/graspsim/snapshot"
SENSOR_TOPIC = "/graspsim/sensor"
STATE_TOPIC = "/graspsim/state"
_RECORD_HEADER = struct.Struct("<BQ")  # opcode, length of the record's content

PathLike = Union[str, "os.PathLike[str]"]


@dataclass
class RecordingData:
    """A recording's frames as arrays; one frame per "/graspsim/snapshot" message (a state the scene published).

    Attributes:
        path: the file read.
        times: (frames,) float64, s, simulation time of each frame; log_times: (frames,) int64, ns (MCAP log_time).
        revisions: (frames,) uint64, the scene revision each frame shows.
        body_ids: the bodies of any frame, in order of first appearance.
        body_poses: (frames, bodies, 7) float64: x y z (m), qw qx qy qz, world; NaN where a body did not exist.
        joint_ids, joint_positions: likewise, (frames, joints) float64, rad or m; NaN where a joint did not exist.
        tactile: sensor id -> (frames, rows, cols) uint16 intensities 0..4095 (0 in a frame without its reading).
        force_torque: joint id -> (frames, 6) float64: force x y z (N), torque x y z (N m), the joint's child
            frame; NaN in a frame without its reading.
        states: frames with a "/graspsim/state" message (the replayable whole state).
        messages_per_topic: topic -> messages read, every channel of the file.
        truncated: the file ended inside a record or before its footer (its writer died); everything complete before
            that point was read. bytes_read: where the complete records end.
    """

    path: Path
    times: NDArray[np.float64]
    log_times: NDArray[np.int64]
    revisions: NDArray[np.uint64]
    body_ids: List[str]
    body_poses: NDArray[np.float64]
    joint_ids: List[str]
    joint_positions: NDArray[np.float64]
    tactile: Dict[str, NDArray[np.uint16]]
    force_torque: Dict[str, NDArray[np.float64]]
    states: int
    messages_per_topic: Dict[str, int]
    truncated: bool
    bytes_read: int

    @property
    def frames(self) -> int:
        return len(self.times)

    def __len__(self) -> int:
        return self.frames

    def tactile_sums(self) -> Dict[str, NDArray[np.int64]]:
        """sensor id -> (frames,) int64, the intensity sum of each frame."""
        return {k: v.reshape(len(v), -1).sum(axis=1, dtype=np.int64) for k, v in self.tactile.items()}


def complete_prefix(path: PathLike) -> Tuple[int, bool]:
    """(offset where the file's last complete record ends, whether the file is truncated), from the records'
    framing alone (opcode, length): no record is decoded. A complete file ends with its footer and magic.
    A file shorter than the magic (empty: nothing written yet) is (0, True).

    ValueError when the file does not start with the MCAP magic.
    """
    size = os.path.getsize(path)
    with open(path, "rb") as f:
        start = f.read(len(MAGIC))
        if len(start) < len(MAGIC) and MAGIC.startswith(start):
            return 0, True  # its writer died (or was not flushed yet) before the magic was out: no record
        if start != MAGIC:
            raise ValueError(f"{path}: not an MCAP file (no MCAP magic at its start)")
        offset = len(MAGIC)
        while offset + _RECORD_HEADER.size <= size:
            f.seek(offset)
            opcode, length = _RECORD_HEADER.unpack(f.read(_RECORD_HEADER.size))
            end = offset + _RECORD_HEADER.size + length
            # Opcode 0 (not an MCAP record) is what a file extended with zeros by a crash holds.
            if opcode == 0 or end > size:
                return offset, True
            offset = end
            if opcode == Opcode.FOOTER:
                f.seek(offset)
                if f.read(len(MAGIC)) != MAGIC:
                    return offset, True
                return offset + len(MAGIC), False
    return offset, True


class _Prefix(io.RawIOBase):
    """The first `limit` bytes of a binary file, as a raw stream."""

    def __init__(self, file: IO[bytes], limit: int) -> None:
        self._file = file
        self._left = limit

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:  # a writable buffer (memoryview)
        n = min(len(buffer), self._left)
        if n <= 0:
            return 0
        data = self._file.read(n)
        buffer[:len(data)] = data
        self._left -= len(data)
        return len(data)


def iter_records(path: PathLike) -> Generator[Any, None, Tuple[int, bool]]:
    """Yields the MCAP records of a file front to back with mcap's StreamReader (chunks opened into their
    records, CRCs checked), stopping cleanly after the last complete record of a truncated file. The generator's
    return value (StopIteration.value) is (bytes_read, truncated).

    In a truncated file (no footer: its writer died) a chunk that fails its CRC or does not decompress also ends
    the reading there: what a crash left in the file's last blocks (e.g. zeros after a power loss) is not data.
    In a finished file it raises.
    """
    end, truncated = complete_prefix(path)
    if end == 0:
        return end, truncated
    with open(path, "rb") as f:
        reader = StreamReader(io.BufferedReader(_Prefix(f, end)), validate_crcs=True, record_size_limit=None)
        try:
            yield from reader.records
        except EndOfFile:
            if not truncated:
                raise
        except Exception:  # noqa: BLE001 — CRCValidationError, zstd's and lz4's errors: a damaged tail
            if not truncated:
                raise
    return end, truncated


def read(path: PathLike) -> RecordingData:
    """Reads a recording's graspsim channels into arrays (see RecordingData); works on a finished file and on one
    whose writer died. ValueError when the file is not MCAP or its messages do not match the graspsim.v1 API."""
    path = Path(path)
    topics: Dict[int, str] = {}
    counts: Counter[str] = Counter()
    snapshots: List[scene_pb2.SceneSnapshot] = []
    snapshot_log_times: List[int] = []
    readings: List[Tuple[int, tactile_pb2.SensorReading]] = []
    state_log_times: List[int] = []
    records = iter_records(path)
    while True:
        try:
            record = next(records)
        except StopIteration as stop:
            bytes_read, truncated = stop.value
            break
        if isinstance(record, Channel):
            topics[record.id] = record.topic
            continue
        if not isinstance(record, Message):
            continue
        topic = topics.get(record.channel_id)
        if topic is None:
            raise ValueError(f"{path}: a message on channel {record.channel_id} before that channel's record")
        counts[topic] += 1
        try:
            if topic == SNAPSHOT_TOPIC:
                snapshots.append(scene_pb2.SceneSnapshot.FromString(record.data))
                snapshot_log_times.append(record.log_time)
            elif topic == SENSOR_TOPIC:
                readings.append((record.log_time, tactile_pb2.SensorReading.FromString(record.data)))
            elif topic == STATE_TOPIC:
                recording_pb2.RecordedState.FromString(record.data)
                state_log_times.append(record.log_time)
        except Exception as err:  # a DecodeError: the message is not what the channel says
            raise ValueError(f"{path}: a message on {topic} at log_time {record.log_time} ns does not decode: "
                             f"{err}") from None
    return _assemble(path, snapshots, snapshot_log_times, readings, state_log_times, dict(counts), truncated,
                     bytes_read)


def _occurrence_keys(log_times: Iterable[int]) -> List[Tuple[int, int]]:
    """(log_time, k): the k-th message at that log_time. Frames of one simulation time (edits between steps)
    and their sensor readings pair up by k."""
    seen: Counter[int] = Counter()
    keys = []
    for t in log_times:
        keys.append((int(t), seen[t]))
        seen[t] += 1
    return keys


def _index(ids_per_frame: Iterable[Iterable[str]]) -> List[str]:
    return list(dict.fromkeys(i for ids in ids_per_frame for i in ids))


def _assemble(path: Path, snapshots: List[scene_pb2.SceneSnapshot], snapshot_log_times: List[int],
              readings: List[Tuple[int, tactile_pb2.SensorReading]], state_log_times: List[int],
              counts: Dict[str, int], truncated: bool, bytes_read: int) -> RecordingData:
    frames = len(snapshots)
    body_ids = _index(s.body_ids for s in snapshots)
    joint_ids = _index(s.joint_ids for s in snapshots)
    body_column = {b: i for i, b in enumerate(body_ids)}
    joint_column = {j: i for i, j in enumerate(joint_ids)}
    poses = np.full((frames, len(body_ids), 7), np.nan)
    joints = np.full((frames, len(joint_ids)), np.nan)
    for i, s in enumerate(snapshots):
        values = np.frombuffer(s.body_poses, dtype="<f8")
        positions = np.frombuffer(s.joint_positions, dtype="<f8")
        if values.size != 7 * len(s.body_ids) or positions.size != len(s.joint_ids):
            raise ValueError(f"{path}: snapshot {i} (t = {s.time:g} s) has {values.size} pose values for "
                             f"{len(s.body_ids)} bodies and {positions.size} positions for {len(s.joint_ids)} joints")
        poses[i, [body_column[b] for b in s.body_ids]] = values.reshape(-1, 7)
        joints[i, [joint_column[j] for j in s.joint_ids]] = positions

    frame_of = {key: i for i, key in enumerate(_occurrence_keys(snapshot_log_times))}
    by_sensor: Dict[str, List[Tuple[int, tactile_pb2.SensorReading]]] = defaultdict(list)
    for log_time, reading in readings:
        by_sensor[reading.sensor_id].append((log_time, reading))
    tactile: Dict[str, NDArray[np.uint16]] = {}
    force_torque: Dict[str, NDArray[np.float64]] = {}
    for sensor_id, items in by_sensor.items():
        keys = _occurrence_keys(t for t, _ in items)
        for key, (_, reading) in zip(keys, items):
            frame = frame_of.get(key)
            if frame is None:
                continue  # a reading whose snapshot the truncation cut off
            kind = reading.WhichOneof("reading")
            if kind == "tactile":
                t = reading.tactile
                image = np.frombuffer(t.intensities, dtype="<u2")
                if image.size != t.rows * t.cols:
                    raise ValueError(f"{path}: {sensor_id} at frame {frame}: {image.size} intensities for "
                                     f"{t.rows} x {t.cols} texels")
                image_array = tactile.get(sensor_id)
                if image_array is None:
                    image_array = tactile[sensor_id] = np.zeros((frames, t.rows, t.cols), dtype=np.uint16)
                if image_array.shape[1:] != (t.rows, t.cols):
                    raise ValueError(f"{path}: {sensor_id} changes shape from {image_array.shape[1:]} to "
                                     f"{(t.rows, t.cols)} at frame {frame}")
                image_array[frame] = image.reshape(t.rows, t.cols)
            elif kind == "force_torque":
                wrench = force_torque.get(sensor_id)
                if wrench is None:
                    wrench = force_torque[sensor_id] = np.full((frames, 6), np.nan)
                f, m = reading.force_torque.force, reading.force_torque.torque
                wrench[frame] = (f.x, f.y, f.z, m.x, m.y, m.z)
    states = sum(1 for key in _occurrence_keys(state_log_times) if key in frame_of)
    return RecordingData(
        path=path, times=np.array([s.time for s in snapshots], dtype=np.float64),
        log_times=np.array(snapshot_log_times, dtype=np.int64),
        revisions=np.array([s.revision for s in snapshots], dtype=np.uint64), body_ids=body_ids, body_poses=poses,
        joint_ids=joint_ids, joint_positions=joints, tactile=tactile, force_torque=force_torque, states=states,
        messages_per_topic=counts, truncated=truncated, bytes_read=bytes_read)


def _max(values: ArrayLike) -> float:
    """The largest value, NaN ignored (0 for none; NaN when every value is NaN)."""
    array = np.asarray(values, dtype=np.float64)
    if array.size == 0:
        return 0.0
    if np.isnan(array).all():
        return float("nan")
    return float(np.nanmax(array))


def rotation_angle(qa: NDArray[np.float64], qb: NDArray[np.float64]) -> NDArray[np.float64]:
    """The angle (rad, 0..pi) of the rotation between unit quaternions (w, x, y, z) along the last axis:
    2 atan2(|v|, |w|) of conj(qa) qb, exactly 0 for equal quaternions and accurate at small angles."""
    wa, va = qa[..., 0], qa[..., 1:]
    wb, vb = qb[..., 0], qb[..., 1:]
    w = wa * wb + np.sum(va * vb, axis=-1)
    v = wa[..., None] * vb - wb[..., None] * va - np.cross(va, vb)
    angle: NDArray[np.float64] = 2.0 * np.arctan2(np.linalg.norm(v, axis=-1), np.abs(w))
    return angle


def compare(a: Union[RecordingData, PathLike], b: Union[RecordingData, PathLike]
            ) -> Dict[str, Union[int, float, str]]:
    """How far two recordings differ, frame by frame at equal simulation time (MCAP log_time, ns; the k-th frame
    of a time in one against the k-th of that time in the other), over the bodies, joints and tactile arrays both
    have. Differences are maxima over frames and bodies:

        frames_compared, frames_only_in_a, frames_only_in_b, bodies_compared, joints_compared, sensors_compared,
        max_position_diff_m          |p_a - p_b|, m
        max_orientation_diff_rad     the angle of the rotation between the two orientations, rad
        max_joint_diff               |q_a - q_b|, rad or m
        max_tactile_sum_diff         |sum_a - sum_b| of a pad's intensities
        max_position_diff_body, max_position_diff_time_s   where the largest position difference is ("" / nan
                                                           when nothing differs)

    A recording against itself is all zeros. With no frame in common the differences are NaN.
    """
    a = a if isinstance(a, RecordingData) else read(a)
    b = b if isinstance(b, RecordingData) else read(b)
    keys_a = _occurrence_keys(a.log_times)
    index_b = {key: i for i, key in enumerate(_occurrence_keys(b.log_times))}
    pairs = [(i, index_b[key]) for i, key in enumerate(keys_a) if key in index_b]
    fa = np.array([i for i, _ in pairs], dtype=np.intp)
    fb = np.array([j for _, j in pairs], dtype=np.intp)
    bodies = [x for x in a.body_ids if x in set(b.body_ids)]
    joints = [x for x in a.joint_ids if x in set(b.joint_ids)]
    sensors = sorted(set(a.tactile) & set(b.tactile))
    report: Dict[str, Union[int, float, str]] = {
        "frames_compared": len(pairs), "frames_only_in_a": a.frames - len(pairs),
        "frames_only_in_b": b.frames - len(pairs), "bodies_compared": len(bodies),
        "joints_compared": len(joints), "sensors_compared": len(sensors)}
    if not pairs:
        nan = float("nan")
        report.update(max_position_diff_m=nan, max_orientation_diff_rad=nan, max_joint_diff=nan,
                      max_tactile_sum_diff=nan, max_position_diff_body="", max_position_diff_time_s=nan)
        return report
    ca = [a.body_ids.index(x) for x in bodies]
    cb = [b.body_ids.index(x) for x in bodies]
    pa, pb = a.body_poses[fa][:, ca], b.body_poses[fb][:, cb]
    position = np.linalg.norm(pa[..., :3] - pb[..., :3], axis=-1)
    angle = rotation_angle(pa[..., 3:], pb[..., 3:])
    ja = a.joint_positions[fa][:, [a.joint_ids.index(x) for x in joints]]
    jb = b.joint_positions[fb][:, [b.joint_ids.index(x) for x in joints]]
    sums_a, sums_b = a.tactile_sums(), b.tactile_sums()
    tactile = [np.abs(sums_a[s][fa] - sums_b[s][fb]) for s in sensors]
    where_body, where_time = "", float("nan")
    if position.size and np.nanmax(np.nan_to_num(position, nan=-1.0)) > 0:
        frame, body = np.unravel_index(np.nanargmax(np.nan_to_num(position, nan=-1.0)), position.shape)
        where_body, where_time = bodies[body], float(a.times[fa[frame]])
    report.update(max_position_diff_m=_max(position), max_orientation_diff_rad=_max(angle),
                  max_joint_diff=_max(np.abs(ja - jb)),
                  max_tactile_sum_diff=_max(np.concatenate(tactile)) if tactile else 0.0,
                  max_position_diff_body=where_body, max_position_diff_time_s=where_time)
    return report
