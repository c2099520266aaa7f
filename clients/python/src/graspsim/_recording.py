"""RecordingService methods of Client (docs/recording.md): a scene's run recorded as MCAP, downloaded, replayed.

A recording is one .mcap file in the server's recording directory (graspsim's own channels, Foxglove's schemas)
and, with the "ros2" group, a ROS 2 bag directory beside it. graspsim.mcap reads a downloaded file into numpy.
"""
from __future__ import annotations

import contextlib
import dataclasses
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator, List, Optional, Sequence, Tuple, Union

import grpc
import numpy as np
from numpy.typing import NDArray
from google.protobuf.message import Message

from graspsim._errors import GraspsimError, translated_errors
from graspsim._ids import SceneLike, scene_id_of
from graspsim._stream import server_stream
from graspsim.v1 import recording_pb2, recording_pb2_grpc

@dataclass
class RecordingInfo:
    """A recording as the server describes it (graspsim.v1.Recording).

    Attributes:
        name: the file name in the server's recording directory (also the recording's id), e.g. "run.mcap".
        scene_id: the recorded scene.
        path: the file on the server; ros2_path: the ROS 2 bag directory beside it ("" without the "ros2" group).
        active: still being written.
        frames: scene states recorded; messages: MCAP messages written, every channel.
        dropped_frames: states the server's writer could not keep up with (its queue was full).
        bytes: the file's size so far.
        start_time, end_time: s, simulation time of the first and of the last frame.
    """

    name: str
    scene_id: str
    path: str
    ros2_path: str
    active: bool
    frames: int
    messages: int
    dropped_frames: int
    bytes: int
    start_time: float
    end_time: float

    @classmethod
    def from_proto(cls, msg: recording_pb2.Recording) -> RecordingInfo:
        return cls(name=msg.name, scene_id=msg.scene_id, path=msg.path, ros2_path=msg.ros2_path,
                   active=msg.active, frames=msg.frames, messages=msg.messages,
                   dropped_frames=msg.dropped_frames, bytes=msg.bytes, start_time=msg.start_time,
                   end_time=msg.end_time)

    def _update(self, other: RecordingInfo) -> None:
        for f in dataclasses.fields(self):
            setattr(self, f.name, getattr(other, f.name))


@dataclass(frozen=True)
class Replay:
    """ReplayRecording's answer: the new scene (in the recording's first state) and the recorded frames.

    Attributes:
        scene_id: the new scene; seek_replay(replay, name, frame) puts it into a frame's state.
        name: the recording it was built from.
        frame_times: (frames,) float64, s, the simulation time of each frame.
    """

    scene_id: str
    name: str
    frame_times: NDArray[np.float64]

    @property
    def frames(self) -> int:
        return len(self.frame_times)


def _create_beside(target: Path) -> Tuple[int, str]:
    """A new file ".<name>.<random>.partial" beside target, opened for writing with the mode a plain open() would
    give it (0666 less the umask; tempfile.mkstemp's would be 0600)."""
    while True:
        partial = str(target.with_name(f".{target.name}.{os.urandom(4).hex()}.partial"))
        try:
            return os.open(partial, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666), partial
        except FileExistsError:
            continue


class RecordingMethods:
    """Mixed into Client; needs self.channel and self.call_timeout."""

    channel: grpc.Channel
    call_timeout: float

    @property
    def recording_stub(self) -> recording_pb2_grpc.RecordingServiceStub:
        stub = self.__dict__.get("_recording_stub")
        if stub is None:
            stub = self.__dict__["_recording_stub"] = recording_pb2_grpc.RecordingServiceStub(self.channel)
        return stub

    def _recording_call(self, method: str, request: Message) -> Any:  # Any: the generated stubs are untyped
        with translated_errors():
            return getattr(self.recording_stub, method)(request, timeout=self.call_timeout)

    def start_recording(self, scene: SceneLike, name: Optional[str] = None, groups: Optional[Sequence[str]] = None,
                        compression: Optional[str] = None,
                        force_torque_joints: Optional[Sequence[str]] = None,
                        rate_hz: Optional[float] = None) -> RecordingInfo:
        """Starts recording a scene into the server's recording directory: every state the scene publishes from
        now on (each simulation chunk and edit) becomes a frame, at most rate_hz per simulated second (None: the
        server's 30; states closer than 1/rate_hz are skipped, the last one before the stop kept).

        name: the file name, ending in ".mcap" (letters, digits, '-', '_', '.'; no directories); None: the
        server's "<scene_id>-<UTC time>.mcap". groups: any of "graspsim", "foxglove", "ros2" (None: all three).
        compression: "zstd" (the server's default), "lz4" or "none". force_torque_joints: joint ids whose 6-axis
        force/torque readings are recorded too. A scene has one recording at a time: a second start raises
        GraspsimError(ALREADY_EXISTS).
        """
        request = recording_pb2.StartRecordingRequest(
            scene_id=scene_id_of(scene, "scene"), name=name or "", groups=list(groups or []),
            compression=compression or "", force_torque_joints=list(force_torque_joints or []), rate_hz=rate_hz or 0.0)
        return RecordingInfo.from_proto(self._recording_call("StartRecording", request))

    def stop_recording(self, scene: SceneLike) -> RecordingInfo:
        """Stops the scene's recording: the file is finished (summary, index) and closed."""
        request = recording_pb2.StopRecordingRequest(scene_id=scene_id_of(scene, "scene"))
        return RecordingInfo.from_proto(self._recording_call("StopRecording", request))

    def list_recordings(self) -> List[RecordingInfo]:
        """The active recordings first, then the files in the recording directory by name."""
        reply = self._recording_call("ListRecordings", recording_pb2.ListRecordingsRequest())
        return [RecordingInfo.from_proto(r) for r in reply.recordings]

    def download_recording(self, name: str, path: Union[str, os.PathLike[str]],
                           timeout: Optional[float] = None) -> Path:
        """Streams a recording's .mcap file (finished, or the part written so far) to the local `path`.

        The bytes go to a temporary file beside `path` that replaces it once complete, so `path` never holds
        half a download. Returns `path`. The ROS 2 bag directory is not part of the download (it is the
        server's ros2_path). timeout (s) bounds the whole download (None: no deadline).
        """
        target = Path(path)
        request = recording_pb2.DownloadRecordingRequest(name=name)
        fd, partial = _create_beside(target)
        try:
            with os.fdopen(fd, "wb") as out, \
                    server_stream(self.recording_stub.DownloadRecording(request, timeout=timeout)) as call:
                written = 0
                for chunk in call:
                    if chunk.offset != written:
                        raise GraspsimError.for_code(grpc.StatusCode.DATA_LOSS,
                                            f"DownloadRecording {name!r}: a chunk at offset {chunk.offset}, expected "
                                            f"{written}")
                    out.write(chunk.data)
                    written += len(chunk.data)
            os.replace(partial, target)
        finally:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(partial)
        return target

    @contextlib.contextmanager
    def record(self, scene: SceneLike, path: Union[str, os.PathLike[str], None] = None,
               **start_kwargs: Any) -> Iterator[RecordingInfo]:
        """A with-block recorded: starts (start_recording(scene, **start_kwargs)), yields the RecordingInfo,
        stops on leaving the block, also on an exception, and then, when `path` is given, downloads the file to
        it. After the block the yielded RecordingInfo holds the stopped recording's figures (frames, bytes, ...).

            with client.record(scene_id, "run.mcap", force_torque_joints=["cell/finger_left_joint"]) as info:
                client.run_work_cycle(scene_id, "cell", "cube")
            print(info.frames)

        When the block raised, its exception propagates; a failure to stop or download then is not raised over it.
        """
        info = self.start_recording(scene, **start_kwargs)
        try:
            yield info
        except BaseException:
            with contextlib.suppress(GraspsimError, OSError):
                info._update(self.stop_recording(scene))
                if path is not None:
                    self.download_recording(info.name, path)
            raise
        info._update(self.stop_recording(scene))
        if path is not None:
            self.download_recording(info.name, path)

    def replay_recording(self, name: str, scene_name: Optional[str] = None) -> Replay:
        """A new scene built from a recording (its edits, then its first recorded state); scene_name None: the
        server's "replay of <name>". Returns the scene id and the recorded frames' simulation times (s)."""
        request = recording_pb2.ReplayRecordingRequest(name=name, scene_name=scene_name or "")
        reply = self._recording_call("ReplayRecording", request)
        return Replay(scene_id=reply.scene_id, name=name, frame_times=np.array(reply.frame_times, dtype=np.float64))

    def seek_replay(self, scene: SceneLike, name: str, frame: int) -> Tuple[float, int]:
        """Puts a replayed scene into the state of recorded frame `frame` (an index into Replay.frame_times):
        every body, joint, velocity and contact. Returns (simulation time s, the scene's new revision)."""
        if int(frame) < 0:
            raise ValueError(f"frame must be >= 0, got {frame}")
        request = recording_pb2.SeekReplayRequest(scene_id=scene_id_of(scene, "scene"), name=name, frame=int(frame))
        reply = self._recording_call("SeekReplay", request)
        return reply.time, reply.revision
