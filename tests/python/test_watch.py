"""WatchScene: snapshot contents, cancellation, many concurrent watchers and one that never reads."""
import threading
import time

import grpc
import numpy as np
from graspsim.v1 import scene_pb2, scene_pb2_grpc

WATCHERS = 20
CHANGES = 50
CHANGE_PERIOD_S = 0.04   # 50 changes over ~2 s
DELIVERY_BOUND_S = 2.0   # each watcher sees the final revision this soon after the last change


def test_first_snapshot_matches_scene(client, scene_id):
    client.add_object(scene_id, "ball", sphere=0.02, mass=0.1, pose=[0.1, 0.2, 0.3, 0, 0, 0, 1])
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70", base_pose=[0, 0, 1, 0, 1, 0, 0])
    client.set_joint_positions(scene_id, {"pg70/finger_left_joint": 0.03})
    revision = client.get_scene(scene_id).summary.revision
    with client.watch_scene(scene_id) as watch:
        snap = next(watch)
    assert snap.revision == revision
    poses = client.get_body_poses(scene_id)
    assert set(snap.body_ids) == set(poses) and snap.poses.shape == (len(poses), 7)
    for body_id, pose in poses.items():
        np.testing.assert_array_equal(snap.pose(body_id).as_array(), pose.as_array())
    assert snap.joint_positions.dtype == np.float64
    assert {j: snap.joint_position(j) for j in snap.joint_ids} == client.get_joint_positions(scene_id)
    assert list(watch) == [], "a cancelled watch stops iterating"


def test_cancel_from_another_thread(client, scene_id):
    watch = client.watch_scene(scene_id)
    next(watch)
    timer = threading.Timer(0.2, watch.cancel)
    timer.start()
    assert list(watch) == []
    timer.join()


class Watcher(threading.Thread):
    """Reads one WatchScene stream, recording (sequence, revision, monotonic receive time) per snapshot."""

    def __init__(self, client, scene_id):
        super().__init__(daemon=True)
        self.watch = client.watch_scene(scene_id)
        self.received = []
        self.started = threading.Event()
        self.error = None

    def run(self):
        try:
            for snap in self.watch:
                self.received.append((snap.sequence, snap.revision, time.monotonic()))
                self.started.set()
        except Exception as err:  # reported by the test thread
            self.error = err
            self.started.set()

    def saw(self, revision: int) -> bool:
        return any(r == revision for _, r, _ in self.received)


# The never-reader's channel: a small stream window and no BDP probing, so that its flow-control window
# fills after a few snapshots and the server must hold (and skip) further ones for it.
STALLED_CHANNEL_OPTIONS = [("grpc.http2.bdp_probe", 0), ("grpc.http2.lookahead_bytes", 16384)]


def test_many_watchers_and_one_that_never_reads(client, server, scene_id):
    for i in range(200):  # ~12 kB snapshots
        client.add_object(scene_id, f"ball{i:03d}", sphere=0.01, mass=0.01, pose=[0.01 * i, 0, 1, 1, 0, 0, 0])
    with grpc.insecure_channel(server.address, options=STALLED_CHANNEL_OPTIONS) as stalled_channel:
        stalled = scene_pb2_grpc.SceneServiceStub(stalled_channel).WatchScene(
            scene_pb2.WatchSceneRequest(scene_id=scene_id), timeout=120)
        stalled.initial_metadata()  # the server has accepted the stream; it is not read until the end
        watchers = [Watcher(client, scene_id) for _ in range(WATCHERS)]
        for w in watchers:
            w.start()
        for w in watchers:
            assert w.started.wait(10), "no first snapshot within 10 s"
        for i in range(CHANGES):
            time.sleep(CHANGE_PERIOD_S)
            final = client.set_body_pose(scene_id, "ball000", [0, 0.001 * i, 1, 1, 0, 0, 0])
        deadline = time.monotonic() + DELIVERY_BOUND_S
        while time.monotonic() < deadline and not all(w.saw(final) for w in watchers):
            time.sleep(0.01)
        assert stalled.is_active(), "the never-read stream was closed"
        for w in watchers:
            w.watch.cancel()
            w.join(10)
        late = []
        for snap in stalled:  # the slow reader catches up by skipping to the newest snapshot
            late.append((snap.sequence, snap.revision))
            if snap.revision == final:
                break
        stalled.cancel()
    assert late[-1][1] == final and len(late) < CHANGES, f"never-reader got {late}: queued, not skipped"
    assert all(a[0] < b[0] for a, b in zip(late, late[1:])), f"never-reader sequences: {late}"
    for index, w in enumerate(watchers):
        assert w.error is None, f"watcher {index}: {w.error}"
        assert w.saw(final), f"watcher {index}: final revision {final} not seen; last {w.received[-1][:2]}"
        sequences = [s for s, _, _ in w.received]
        assert all(a < b for a, b in zip(sequences, sequences[1:])), f"watcher {index}: sequences {sequences}"
        revisions = [r for _, r, _ in w.received]
        assert revisions == sorted(revisions), f"watcher {index}: revisions went back: {revisions}"
