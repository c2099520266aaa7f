"""WatchScene as a Python iterator of numpy snapshots."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import List

import grpc
import numpy as np
from numpy.typing import NDArray

from graspsim._stream import CancellableStream, StreamCall
from graspsim._pose import Pose
from graspsim.v1 import scene_pb2


@dataclass(frozen=True)
class Snapshot:
    """One published state of a scene.

    Attributes:
        sequence: per-stream counter, +1 per published snapshot (gaps = snapshots skipped for a slow reader).
        revision: the scene revision shown.
        time: simulation time, s.
        body_ids: order of the rows of poses.
        poses: (N, 7) float64, one row [x y z (m), qw qx qy qz] per body, world frame.
        joint_ids: order of joint_positions.
        joint_positions: (J,) float64, rad or m.
        contacts: (K, 6) float64, the last simulation step's contact points: [x y z (m), fx fy fz (N)], world
            frame, the force acting on the first body of the pair.
        contact_bodies: (K, 2) int, the pair of each contact: indices into body_ids (the first body's surface
            sample lies inside the second).
    """

    sequence: int
    revision: int
    time: float
    body_ids: List[str]
    poses: NDArray[np.float64]
    joint_ids: List[str]
    joint_positions: NDArray[np.float64]
    contacts: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 6)))
    contact_bodies: NDArray[np.int64] = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))

    @classmethod
    def from_proto(cls, msg: scene_pb2.SceneSnapshot) -> Snapshot:
        """Unpacks the little-endian float64 arrays of a SceneSnapshot message."""
        poses = np.frombuffer(msg.body_poses, dtype="<f8").astype(np.float64)
        joints = np.frombuffer(msg.joint_positions, dtype="<f8").astype(np.float64)
        if poses.size != 7 * len(msg.body_ids) or joints.size != len(msg.joint_ids):
            raise ValueError(f"snapshot {msg.sequence}: {poses.size} pose values for {len(msg.body_ids)} bodies, "
                             f"{joints.size} joint values for {len(msg.joint_ids)} joints")
        contacts = np.frombuffer(msg.contacts, dtype="<f8").astype(np.float64)
        pairs = np.frombuffer(msg.contact_bodies, dtype="<u4").astype(np.int64)
        if contacts.size != 3 * pairs.size:
            raise ValueError(f"snapshot {msg.sequence}: {contacts.size} contact values for {pairs.size // 2} pairs")
        return cls(msg.sequence, msg.revision, msg.time, list(msg.body_ids), poses.reshape(-1, 7),
                   list(msg.joint_ids), joints, contacts.reshape(-1, 6), pairs.reshape(-1, 2))

    def pose(self, body_id: str) -> Pose:
        """The world pose of one body; ValueError if the snapshot does not hold it."""
        return Pose.from_array(self.poses[self.body_ids.index(body_id)])

    def joint_position(self, joint_id: str) -> float:
        """The position of one joint, rad or m; ValueError if the snapshot does not hold it."""
        return float(self.joint_positions[self.joint_ids.index(joint_id)])


class SceneWatch(CancellableStream[Snapshot]):
    """Iterator over a WatchScene stream; cancel() (or close(), or leaving a with-block) ends it.

    Iteration blocks until the next snapshot; after cancel() it stops cleanly (StopIteration).
    Server errors are raised as GraspsimError.
    """

    def __init__(self, call: StreamCall) -> None:
        super().__init__(call, Snapshot.from_proto)
