"""Recordings replayed through the real server (issue 25, docs/recording.md): ReplayRecording and SeekReplay to
every recorded state, --record, graspsim.mcap.compare, a recording cut by kill -9, and the server's own MCAP
reader (recording/mcap_reader.cpp, what ReplayRecording reads with) against files written by an independent writer
(PyPI mcap's Writer: lz4 and uncompressed chunks, whole and cut inside a chunk).

Shared pieces (the work-cycle recording, replays sought frame by frame): _recording_support.py.
"""
import os
import signal
import threading
import time
from pathlib import Path

import grpc
import numpy as np
import pytest
from mcap.reader import make_reader
from mcap.records import Channel, Message
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType

import graspsim
import graspsim.mcap

from _recording_support import (EXACT, FT_JOINT, HOLD, LIFT, PADS, SETPOINT, assert_replay_matches_snapshots,
                                rewrite_with_mcap_writer, work_cycle_recording, write_synthetic)
from _support import expect_error
from conftest import ServerProcess


@pytest.fixture(scope="module")
def recorded(server, tmp_path_factory):
    """The work cycle recorded once on the shared server (_recording_support.work_cycle_recording)."""
    return work_cycle_recording(server, tmp_path_factory)


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
        poses = assert_replay_matches_snapshots(client, replay, data)
        for body, pose in final.items():
            np.testing.assert_allclose(poses[body].as_array(), pose.as_array(), **EXACT)


# --- graspsim.mcap on files written here with mcap's own writer (no server) -----------------------------------
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




# --- the server's MCAP reader (ReplayRecording) on files written by mcap's own Writer ----------------------------
REWRITE_CHUNK_BYTES = 2048  # uncompressed records per chunk: a short recording spans several chunks
COMPRESSIONS = pytest.mark.parametrize("compression", [CompressionType.LZ4, CompressionType.NONE],
                                       ids=["lz4", "none"])
CHUNK_COMPRESSION = {CompressionType.LZ4: "lz4", CompressionType.NONE: ""}  # the Chunk record's field


@pytest.fixture(scope="module")
def falling_box(client):
    """A real recording by the shared server: a tilted box falling onto the ground, stepped a few times, and a
    ball added mid-recording, so its AddObject edit lies between frames. (RecordingInfo, its graspsim.mcap data)."""
    scene_id = client.create_scene("falling box").id
    try:
        client.add_object(scene_id, "ground", box=(2, 2, 0.1), is_static=True, pose=[0, 0, -0.05, 1, 0, 0, 0])
        client.add_object(scene_id, "box", box=(0.05, 0.04, 0.03), mass=0.1, pose=[0, 0, 0.3, 0.8, 0.6, 0, 0])
        client.start_recording(scene_id, name="falling-box.mcap")
        for _ in range(4):
            client.step_simulation(scene_id, duration=0.05)
        client.add_object(scene_id, "ball", sphere=0.02, mass=0.1, pose=[0.3, 0, 0.2, 1, 0, 0, 0])
        for _ in range(4):
            client.step_simulation(scene_id, duration=0.05)
        info = client.stop_recording(scene_id)
    finally:
        client.delete_scene(scene_id)
    data = graspsim.mcap.read(info.path)
    assert not data.truncated and data.frames == data.states == info.frames >= 8, info
    assert data.body_ids == ["ground", "box", "ball"] and np.isnan(data.body_poses[0, 2]).all()
    with open(info.path, "rb") as f:
        topics = [c.topic for _, c, _ in make_reader(f).iter_messages(log_time_order=False)]
    first_state = topics.index("/graspsim/state")
    assert "/graspsim/edit" in topics[first_state:], "the ball's edit comes after the first frame"
    return info, data


def states_before_the_cut(path: Path) -> int:
    """/graspsim/state messages that mcap's StreamReader reads from a file cut short, before it meets the cut."""
    channels, states = {}, 0
    with open(path, "rb") as f:
        with pytest.raises(Exception):  # noqa: B017 — EndOfFile, or the chunk the cut runs through
            for record in StreamReader(f).records:
                if isinstance(record, Channel):
                    channels[record.id] = record.topic
                elif isinstance(record, Message) and channels[record.channel_id] == "/graspsim/state":
                    states += 1
    return states


@COMPRESSIONS
def test_server_replays_a_file_written_by_the_mcap_writer(client, falling_box, compression):
    """Every message of a server recording written again by mcap.writer.Writer (lz4 / uncompressed chunks of
    2 kB, so several) under a new name in the recording directory: ReplayRecording reads it with the server's own
    reader, and SeekReplay to every frame puts every body where the original's /graspsim/snapshot says (1e-12)."""
    info, data = falling_box
    name = f"rewritten-{compression.name.lower()}.mcap"
    path = Path(info.path).with_name(name)
    assert rewrite_with_mcap_writer(Path(info.path), path, compression, REWRITE_CHUNK_BYTES) == info.messages
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    assert len(summary.chunk_indexes) >= 3, "several chunks"
    assert {c.compression for c in summary.chunk_indexes} == {CHUNK_COMPRESSION[compression]}
    assert summary.statistics.message_count == info.messages
    replay = client.replay_recording(name)
    try:
        assert replay.frames == data.frames
        np.testing.assert_array_equal(replay.frame_times, data.times)
        poses = assert_replay_matches_snapshots(client, replay, data)
        assert sorted(poses) == ["ball", "box", "ground"]
    finally:
        client.delete_scene(replay.scene_id)


@COMPRESSIONS
def test_server_replays_the_frames_before_a_cut_inside_a_chunk(client, falling_box, compression, tmp_path):
    """The rewritten file cut in the middle of a chunk three quarters in (after the ball's edit): ReplayRecording
    succeeds with the frames whose states lie before the cut (as many as mcap's StreamReader reads there), the
    ball's edit among them, each frame sought to its snapshot."""
    info, data = falling_box
    whole = tmp_path / "whole.mcap"
    rewrite_with_mcap_writer(Path(info.path), whole, compression, REWRITE_CHUNK_BYTES)
    with open(whole, "rb") as f:
        chunks = sorted(make_reader(f).get_summary().chunk_indexes, key=lambda c: c.chunk_start_offset)
    assert len(chunks) >= 3
    chunk = chunks[3 * len(chunks) // 4]
    name = f"cut-{compression.name.lower()}.mcap"
    path = Path(info.path).with_name(name)
    path.write_bytes(whole.read_bytes()[:chunk.chunk_start_offset + chunk.chunk_length // 2])
    expected = states_before_the_cut(path)
    assert 0 < expected < data.frames, (expected, data.frames)
    assert not np.isnan(data.body_poses[expected - 1, data.body_ids.index("ball")]).any(), "cut after the ball"
    replay = client.replay_recording(name)
    try:
        assert replay.frames == expected
        np.testing.assert_array_equal(replay.frame_times, data.times[:expected])
        assert_replay_matches_snapshots(client, replay, data)
    finally:
        client.delete_scene(replay.scene_id)
