"""Client helpers without a server: poses, packing, mass properties, STL, upload chunks, errors."""
import contextlib
import hashlib
import socket
import struct

import grpc
import numpy as np
import pytest

import graspsim
from graspsim import inertia, meshes
from graspsim._upload import upload_chunks
from graspsim._sensors import reading_from_proto
from graspsim._watch import Snapshot
from graspsim.v1 import common_pb2, scene_pb2, tactile_pb2


@contextlib.contextmanager
def unused_port():
    """A port on which nothing listens: bound, without listen(), for the duration of the block."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        yield sock.getsockname()[1]


def test_pose_forms_agree():
    expected = [0.1, 0.2, 0.3, 0.0, 1.0, 0.0, 0.0]
    forms = [graspsim.Pose([0.1, 0.2, 0.3], [0, 1, 0, 0]), expected, np.array(expected),
             ([0.1, 0.2, 0.3], (0, 1, 0, 0)), graspsim.Pose.from_array(expected).to_proto()]
    for form in forms:
        np.testing.assert_array_equal(graspsim.as_pose(form).as_array(), expected)


def test_pose_rejects_wrong_shapes():
    for bad in ([1, 2, 3], [1, 2, 3, 4, 5, 6, 7, 8], ([1, 2], [1, 0, 0, 0]), ([1, 2, 3], [1, 0, 0])):
        with pytest.raises(ValueError):
            graspsim.as_pose(bad)


def test_pose_proto_keeps_zero_quaternion_and_nan():
    msg = graspsim.Pose([np.nan, 0, 0], [0, 0, 0, 0]).to_proto()
    assert msg.HasField("orientation") and msg.orientation.w == 0.0
    assert np.isnan(msg.position.x)
    back = scene_pb2.AddObjectRequest.FromString(scene_pb2.AddObjectRequest(pose=msg).SerializeToString()).pose
    assert back.HasField("orientation")


def test_absent_orientation_is_identity():
    pose = graspsim.Pose.from_proto(common_pb2.Pose(position=common_pb2.Vec3(x=1.0)))
    np.testing.assert_array_equal(pose.orientation, [1, 0, 0, 0])
    np.testing.assert_array_equal(pose.matrix()[:3, 3], [1, 0, 0])


def test_quaternion_about_x_flips_z():
    q = graspsim.quaternion_about_axis([1, 0, 0], np.pi)
    np.testing.assert_allclose(q, [0, 1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(graspsim.quaternion_to_matrix(q), np.diag([1, -1, -1]), atol=1e-15)
    q90 = graspsim.quaternion_about_axis([0, 0, 2], np.pi / 2)
    np.testing.assert_allclose(graspsim.quaternion_to_matrix(q90) @ [1, 0, 0], [0, 1, 0], atol=1e-15)


def test_pack_mesh_little_endian():
    vertices, triangles = meshes.box_mesh([1, 2, 3])
    msg = meshes.pack_mesh(vertices, triangles)
    assert len(msg.vertices) == 8 * 12 and len(msg.triangles) == 12 * 12
    assert struct.unpack_from("<3f", msg.vertices) == (-0.5, -1.0, -1.5)
    assert struct.unpack_from("<3I", msg.triangles) == tuple(int(i) for i in triangles[0])
    v, t = meshes.unpack_mesh(msg)
    np.testing.assert_array_equal(v, vertices)
    np.testing.assert_array_equal(t, triangles)
    with pytest.raises(ValueError):
        meshes.pack_mesh(np.zeros((4, 2)), triangles)


def test_primitive_inertia_formulas():
    np.testing.assert_allclose(inertia.box_inertia(12.0, (1, 2, 3)), np.diag([13.0, 10.0, 5.0]))
    np.testing.assert_allclose(inertia.sphere_inertia(5.0, 2.0), 8.0 * np.eye(3))
    np.testing.assert_allclose(inertia.cylinder_inertia(12.0, 1.0, 2.0), np.diag([7.0, 7.0, 6.0]))


def test_mesh_inertia_matches_box_and_sphere():
    vertices, triangles = meshes.box_mesh([0.1, 0.2, 0.3])
    shifted = vertices + [1.0, -2.0, 0.5]
    com, tensor = inertia.mesh_inertia(2.0, shifted, triangles)
    np.testing.assert_allclose(com, [1.0, -2.0, 0.5], atol=1e-12)
    np.testing.assert_allclose(tensor, inertia.box_inertia(2.0, [0.1, 0.2, 0.3]), atol=1e-12)
    volume, _, _ = inertia.mesh_volume_properties(*meshes.uv_sphere(1.0, 64, 128))
    assert volume == pytest.approx(4.0 / 3.0 * np.pi, rel=2e-3)
    _, sphere = inertia.mesh_inertia(1.0, *meshes.uv_sphere(1.0, 64, 128))
    np.testing.assert_allclose(sphere, 0.4 * np.eye(3), rtol=3e-3, atol=1e-6)


def test_mesh_inertia_rejects_open_or_inverted_mesh():
    vertices, triangles = meshes.box_mesh([1, 1, 1])
    with pytest.raises(ValueError, match="closed"):
        inertia.mesh_inertia(1.0, vertices, triangles[:, ::-1])
    with pytest.raises(ValueError, match="closed"):
        inertia.mesh_inertia(1.0, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.uint32))


def test_uv_sphere_counts():
    vertices, triangles = meshes.uv_sphere(0.5, 11, 10)
    assert len(triangles) == 200 and len(vertices) == 2 + 10 * 10
    assert triangles.max() == len(vertices) - 1
    np.testing.assert_allclose(np.linalg.norm(vertices, axis=1), 0.5)


def test_binary_stl_layout():
    vertices, triangles = meshes.box_mesh([2, 2, 2])
    stl = meshes.to_stl(vertices, triangles)
    assert len(stl) == 84 + 50 * 12
    assert struct.unpack_from("<I", stl, 80) == (12,)
    normal = struct.unpack_from("<3f", stl, 84)
    corners = np.array(struct.unpack_from("<9f", stl, 96)).reshape(3, 3)
    np.testing.assert_allclose(normal, [-1, 0, 0])
    np.testing.assert_allclose(corners, vertices[triangles[0]])


def test_upload_chunks_header_first_then_data():
    data = bytes(range(256)) * 10
    chunks = list(upload_chunks("s1", "meshes/a.stl", data, 1000))
    assert [len(c.data) for c in chunks] == [1000, 1000, 560]
    assert chunks[0].header.total_size == len(data)
    assert chunks[0].header.sha256 == hashlib.sha256(data).hexdigest()
    assert (chunks[0].header.scene_id, chunks[0].header.path) == ("s1", "meshes/a.stl")
    assert not any(c.HasField("header") for c in chunks[1:])
    assert b"".join(c.data for c in chunks) == data


def test_upload_chunks_from_file_and_empty(tmp_path):
    path = tmp_path / "f.bin"
    path.write_bytes(b"x" * 10)
    assert [len(c.data) for c in upload_chunks("s", "f.bin", path, 4)] == [4, 4, 2]
    assert [len(c.data) for c in upload_chunks("s", "f.bin", str(path), 4)] == [4, 4, 2]
    empty = list(upload_chunks("s", "e.bin", b"", 4))
    assert len(empty) == 1 and empty[0].header.total_size == 0
    with pytest.raises(ValueError):
        list(upload_chunks("s", "e.bin", b"", 0))


def test_snapshot_unpacks_packed_arrays():
    poses = np.arange(14, dtype="<f8")
    msg = scene_pb2.SceneSnapshot(sequence=3, revision=7, body_ids=["a", "b"], body_poses=poses.tobytes(),
                                  joint_ids=["j"], joint_positions=np.array([0.5], "<f8").tobytes())
    snap = Snapshot.from_proto(msg)
    assert snap.poses.shape == (2, 7) and snap.poses.dtype == np.float64
    np.testing.assert_array_equal(snap.pose("b").position, [7, 8, 9])
    assert snap.joint_position("j") == 0.5 and (snap.sequence, snap.revision) == (3, 7)
    with pytest.raises(ValueError):
        Snapshot.from_proto(scene_pb2.SceneSnapshot(body_ids=["a"], body_poses=b"\0" * 8))


def test_tactile_reading_unpacks_little_endian_texels():
    intensities = np.arange(6, dtype="<u2") * 700          # 2 rows x 3 cols, row-major
    forces = np.arange(18, dtype="<f4") / 4                # x y z per texel
    msg = tactile_pb2.SensorReading(sensor_id="g/pad", time=1.5, tactile=tactile_pb2.TactileReading(
        rows=2, cols=3, intensities=intensities.tobytes(), forces=forces.tobytes(), intensity_sum=10500,
        force_sum=common_pb2.Vec3(x=1, y=2, z=3)))
    frame = reading_from_proto(msg)
    assert isinstance(frame, graspsim.TactileFrame)
    assert (frame.sensor_id, frame.time, frame.rows, frame.cols, frame.intensity_sum) == ("g/pad", 1.5, 2, 3, 10500)
    assert frame.intensities.dtype == np.uint16 and frame.intensities.shape == (2, 3)
    assert frame.intensities[1, 0] == 2100, "row-major: texel (1, 0) is the fourth value"
    assert frame.forces.dtype == np.float32 and frame.forces.shape == (2, 3, 3)
    np.testing.assert_array_equal(frame.forces[1, 2], [3.75, 4.0, 4.25])
    np.testing.assert_array_equal(frame.force_sum, [1, 2, 3])
    with pytest.raises(ValueError, match="2 x 3"):
        msg.tactile.forces = forces[:-3].tobytes()
        reading_from_proto(msg)


def test_gripper_reading_and_unknown_kind():
    msg = tactile_pb2.SensorReading(sensor_id="g/gripper", time=0.25, gripper=tactile_pb2.GripperReading(
        finger_distance=0.06, motor_current=-1.5, finger_velocity=-0.02))
    assert reading_from_proto(msg) == graspsim.GripperState("g/gripper", 0.25, 0.06, -1.5, -0.02)
    msg = tactile_pb2.SensorReading(sensor_id="r/j", time=0.5, force_torque=tactile_pb2.ForceTorqueReading(
        force=common_pb2.Vec3(x=1, y=-2, z=3.5), torque=common_pb2.Vec3(x=-0.25, y=0, z=0.125)))
    reading = reading_from_proto(msg)
    assert isinstance(reading, graspsim.ForceTorqueState) and (reading.sensor_id, reading.time) == ("r/j", 0.5)
    np.testing.assert_array_equal(reading.force, [1, -2, 3.5])
    np.testing.assert_array_equal(reading.torque, [-0.25, 0, 0.125])
    assert reading.force.dtype == np.float64 and reading.torque.shape == (3,)
    with pytest.raises(ValueError, match="kind None"):
        reading_from_proto(tactile_pb2.SensorReading(sensor_id="j"))


def test_error_str_names_code():
    err = graspsim.GraspsimError(grpc.StatusCode.NOT_FOUND, "scene 'x' not found")
    assert str(err) == "NOT_FOUND: scene 'x' not found"
    assert isinstance(err, Exception) and err.code == grpc.StatusCode.NOT_FOUND


def test_add_object_argument_checks():
    client = graspsim.Client(grpc.insecure_channel("127.0.0.1:1"))
    with pytest.raises(ValueError, match="exactly one"):
        client.add_object("s", "o", box=(1, 1, 1), sphere=1.0, mass=1.0)
    with pytest.raises(ValueError, match="inertia"):
        client.add_object("s", "o", mesh_file="a.stl", mass=1.0)
    with pytest.raises(ValueError, match="symmetric"):
        client.add_object("s", "o", box=(1, 1, 1), mass=1.0, inertia=[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]])
    with pytest.raises(ValueError, match="exactly one"):
        client.add_robot("s", "r")
    client.close()


def test_connect_without_server_is_unavailable():
    with unused_port() as port:
        with pytest.raises(graspsim.GraspsimError) as info:
            graspsim.connect(f"127.0.0.1:{port}", timeout=0.5)
    assert info.value.code == grpc.StatusCode.UNAVAILABLE and "127.0.0.1" in info.value.message


def work_cycle_message(stage, t, left, right, z, axis=0.1, limit=1.0, rows=2, cols=3):
    """A hand-made WorkCycleProgress: pads filled with `left` / `right` per texel, the cube at height z."""
    def pad(name, value):
        values = np.full(rows * cols, value, dtype="<u2")
        return tactile_pb2.SensorReading(sensor_id=f"cell/pad_{name}", time=t, tactile=tactile_pb2.TactileReading(
            rows=rows, cols=cols, intensities=values.tobytes(), forces=np.zeros(3 * rows * cols, "<f4").tobytes(),
            intensity_sum=int(values.sum())))
    gripper = tactile_pb2.SensorReading(sensor_id="cell/gripper", time=t, gripper=tactile_pb2.GripperReading(
        finger_distance=0.05, motor_current=limit / 2, finger_velocity=-0.01))
    pose = graspsim.Pose([0.0, 0.0, z], [1, 0, 0, 0]).to_proto()
    return tactile_pb2.WorkCycleProgress(stage=stage, time=t, object_pose=pose, axis_position=axis,
                                         current_limit=limit, readings=[pad("left", left), pad("right", right),
                                                                        gripper])


# (stage, t, left per texel, right per texel, cube z, axis): 6 texels, set-point 6000 -> 1000 per texel
CYCLE = [("approach", 0.0, 0, 0, 0.775, 0.00), ("approach", 0.1, 0, 0, 0.775, 0.05),
         ("grasp", 0.2, 0, 0, 0.775, 0.10), ("grasp", 0.3, 400, 380, 0.775, 0.10),
         ("grasp", 0.4, 950, 940, 0.775, 0.10), ("lift", 0.5, 1000, 990, 0.775, 0.10),
         ("lift", 0.6, 1000, 995, 0.800, 0.075), ("hold", 0.7, 1000, 990, 0.8245, 0.05),
         ("hold", 0.8, 1010, 1000, 0.8245, 0.05), ("move_down", 0.9, 1000, 1000, 0.80, 0.075),
         ("release", 1.0, 200, 210, 0.7751, 0.10), ("done", 1.1, 0, 0, 0.7751, 0.0)]


def work_cycle_result(**settings):
    messages = [work_cycle_message(s, t, l, r, z, axis) for s, t, l, r, z, axis in CYCLE]
    return graspsim.WorkCycleResult.from_progress(messages, **settings)


def test_work_cycle_frame_decodes_pads_gripper_and_pose():
    frame = graspsim.WorkCycleFrame.from_proto(work_cycle_message("grasp", 0.3, 400, 380, 0.775, limit=1.5))
    assert (frame.stage, frame.time, frame.axis_position, frame.current_limit) == ("grasp", 0.3, 0.1, 1.5)
    assert (frame.left.sensor_id, frame.right.sensor_id) == ("cell/pad_left", "cell/pad_right")
    assert frame.left.intensity_sum == 2400 and frame.right.intensities[1, 2] == 380
    assert frame.gripper == graspsim.GripperState("cell/gripper", 0.3, 0.05, 0.75, -0.01)
    np.testing.assert_array_equal(frame.object_pose.position, [0, 0, 0.775])
    broken = work_cycle_message("grasp", 0.3, 1, 1, 0.775)
    del broken.readings[2]
    with pytest.raises(ValueError, match="2 tactile and 0 gripper"):
        graspsim.WorkCycleFrame.from_proto(broken)


def test_work_cycle_result_time_series():
    result = work_cycle_result(tactile_setpoint=6000)
    n = len(CYCLE)
    assert len(result) == n and result.stage == [c[0] for c in CYCLE]
    assert result.stages() == ["approach", "grasp", "lift", "hold", "move_down", "release", "done"]
    np.testing.assert_allclose(result.time, [c[1] for c in CYCLE])
    np.testing.assert_array_equal(result.left_sum, [6 * c[2] for c in CYCLE])
    np.testing.assert_array_equal(result.right_sum, [6 * c[3] for c in CYCLE])
    assert result.left_images.shape == result.right_images.shape == (n, 2, 3)
    assert result.left_images.dtype == np.uint16 and result.left_images[4, 1, 1] == 950
    for name in ("finger_distance", "motor_current", "finger_velocity", "axis_position", "current_limit"):
        assert getattr(result, name).shape == (n,) and getattr(result, name).dtype == np.float64, name
    assert result.object_position.shape == (n, 3) and result.object_orientation.shape == (n, 4)
    np.testing.assert_array_equal(result.object_orientation[-1], [1, 0, 0, 0])
    np.testing.assert_allclose(result.object_position[:, 2], [c[4] for c in CYCLE])
    assert (result.left_id, result.right_id, result.gripper_sensor_id) == ("cell/pad_left", "cell/pad_right",
                                                                            "cell/gripper")
    assert result.stage_starts() == [("approach", 0.0), ("grasp", 0.2), ("lift", 0.5), ("hold", 0.7),
                                     ("move_down", 0.9), ("release", 1.0), ("done", 1.1)]
    assert result.stage_spans()[1] == ("grasp", 0.2, 0.4)
    assert result.stage_mask("hold").tolist() == [False] * 7 + [True] * 2 + [False] * 3


def test_work_cycle_defaults_and_empty_result():
    result = work_cycle_result()
    assert (result.tactile_setpoint, result.lift_height, result.coverage) == (60000.0, 0.05, 1.0)
    assert work_cycle_result(coverage=0.15, lift_height=0.02).coverage == 0.15
    empty = graspsim.WorkCycleResult.from_frames([])
    assert len(empty) == 0 and empty.left_images.shape == (0, 0, 0) and empty.object_position.shape == (0, 3)
    assert empty.stage_spans() == [] and empty.peak_index() == -1
    assert np.isnan(empty.summary().lift) and empty.summary().peak_left == 0.0


def test_work_cycle_rejects_pads_that_change_shape():
    messages = [work_cycle_message("grasp", 0.0, 1, 1, 0.775), work_cycle_message("grasp", 0.1, 1, 1, 0.775, rows=3)]
    with pytest.raises(ValueError, match="different shapes"):
        graspsim.WorkCycleResult.from_progress(messages)


def test_work_cycle_summary():
    summary = work_cycle_result(tactile_setpoint=6000).summary()
    assert (summary.peak_left, summary.peak_right) == (6060.0, 6000.0)
    assert summary.peak_mismatch == pytest.approx(60 / 6030)
    assert summary.hold_mismatch == pytest.approx(max(60 / 5970, 60 / 6030))
    assert summary.first_contact_time == pytest.approx(0.3)
    assert summary.rise_time == pytest.approx(0.1), "mean 945 per texel >= 90 % of 1000 at t = 0.4"
    assert summary.lift == pytest.approx(0.0495) and summary.slip == pytest.approx(0.0005)
    assert summary.final_offset == pytest.approx(0.0001)


def test_run_work_cycle_streams_frames_through_a_fake_stub():
    class FakeCall:
        def __init__(self, messages, error=None):
            self.messages, self.error, self.cancelled = messages, error, False

        def __iter__(self):
            yield from self.messages
            if self.error is not None:
                raise self.error

        def cancel(self):
            self.cancelled = True

    class RpcFailure(grpc.RpcError):
        def code(self):
            return grpc.StatusCode.INVALID_ARGUMENT

        def details(self):
            return "coverage 1.5 is outside (0, 1]"

    client = graspsim.Client(grpc.insecure_channel("127.0.0.1:1"))
    requests, seen = [], []
    messages = [work_cycle_message(s, t, l, r, z, axis) for s, t, l, r, z, axis in CYCLE]
    call = FakeCall(messages)

    class FakeStub:
        def RunWorkCycle(self, request, timeout=None):
            requests.append(request)
            return call

    client.tactile_stub = FakeStub()
    result = client.run_work_cycle("s", "cell", "cube", coverage=0.6, hold_time=0.2, on_frame=seen.append)
    assert (requests[0].scene_id, requests[0].gripper_id, requests[0].object_id) == ("s", "cell", "cube")
    assert (requests[0].coverage, requests[0].hold_time, requests[0].tactile_setpoint) == (0.6, 0.2, 0.0)
    assert [f.stage for f in seen] == result.stage and isinstance(seen[0], graspsim.WorkCycleFrame)
    assert result.coverage == 0.6 and len(result) == len(CYCLE)

    call = FakeCall(messages[:2], RpcFailure())
    with pytest.raises(graspsim.GraspsimError, match="coverage") as info:
        client.run_work_cycle("s", "cell", "cube", coverage=1.5)
    assert info.value.code == grpc.StatusCode.INVALID_ARGUMENT and call.cancelled

    call = FakeCall(messages)

    def stop(frame):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        client.run_work_cycle("s", "cell", "cube", on_frame=stop)
    assert call.cancelled, "a callback that raises cancels the cycle"
    client.close()


def test_plot_helpers_draw_and_save(tmp_path):
    pytest.importorskip("matplotlib")
    import graspsim.plot

    result = work_cycle_result(tactile_setpoint=6000)
    fig = graspsim.plot.work_cycle_figure({"15 %": result, "100 %": work_cycle_result(tactile_setpoint=6000)})
    top = fig.axes[0]
    assert len(top.get_lines()) >= 4 and top.get_ylabel() == "tactile sum (intensity)"
    png = graspsim.plot.save(fig, tmp_path / "cycle.png")
    assert open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
    fig = graspsim.plot.new_figure()
    ax = fig.subplots()
    lines = graspsim.plot.sums_over_time(ax, result)
    np.testing.assert_array_equal(lines[1].get_ydata(), result.right_sum)
    image = graspsim.plot.tactile_image(fig.add_subplot(2, 2, 4), result.left_images[4])
    assert image.get_array().shape == (2, 3) and image.get_clim() == (0, 4095)
    frame = graspsim.WorkCycleFrame.from_proto(work_cycle_message("grasp", 0.3, 400, 380, 0.775)).left
    assert "cell/pad_left" in graspsim.plot.tactile_image(ax, frame).axes.get_title()
    with pytest.raises(ValueError, match="rows, cols"):
        graspsim.plot.tactile_image(ax, np.zeros(3))
    graspsim.plot.save(graspsim.plot.peak_images_figure(result), tmp_path / "peak.png")
    assert (tmp_path / "peak.png").stat().st_size > 0


def test_base_client_does_not_import_matplotlib():
    import subprocess
    import sys
    code = "import sys, graspsim; sys.exit('matplotlib' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


@pytest.mark.parametrize("name", ["gateway_rig", "partial_view"])
def test_moved_test_rigs_keep_their_old_names_for_a_release(name, monkeypatch):
    import importlib
    import sys
    monkeypatch.delitem(sys.modules, f"graspsim.{name}", raising=False)  # imported afresh: the warning again
    with pytest.warns(DeprecationWarning, match=f"graspsim.testing.{name}"):
        old = importlib.import_module(f"graspsim.{name}")
    assert old is importlib.import_module(f"graspsim.testing.{name}")
