"""TactileService.RunWorkCycle through the real server: a PG70 on a z axis picks the 5 cm cube and puts it back."""
import grpc
import numpy as np
import pytest

import graspsim
from graspsim._work_cycle import STAGES

from _support import IA, assert_rejected

TABLE_TOP = 0.75   # m, built-in table
CUBE = 0.05        # m, built-in cube_5cm edge
BASE_Z = 1.05      # m, the cell's axis_base (as clients/python/examples/tactile_cycle.py)
LIFT = 0.03        # m
HOLD = 0.3         # s
SETPOINT = 60000.0


@pytest.fixture
def cell(client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
    client.add_robot(scene_id, "cell", builtin="schunk_pg70_on_z_axis", base_pose=[0, 0, BASE_Z, 1, 0, 0, 0])
    return scene_id


@pytest.fixture(scope="module")
def cycle(server):
    """One work cycle at full coverage on a scene of its own (shared by the tests that only read it)."""
    with graspsim.connect(server.address) as client:
        scene_id = client.create_scene("test_work_cycle").id
        client.add_object(scene_id, "table", builtin="table")
        client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
        client.add_robot(scene_id, "cell", builtin="schunk_pg70_on_z_axis", base_pose=[0, 0, BASE_Z, 1, 0, 0, 0])
        frames = []
        result = client.run_work_cycle(scene_id, "cell", "cube", lift_height=LIFT, hold_time=HOLD,
                                       tactile_setpoint=SETPOINT, on_frame=frames.append, timeout=120)
        client.delete_scene(scene_id)
    return result, frames


def test_frames_cover_every_stage_in_order(cycle):
    result, frames = cycle
    assert [name for name, _, _ in result.stage_spans()] == list(STAGES), "each stage once, in order"
    assert result.stage[-1] == "done"
    assert np.all(np.diff(result.time) > 0), "simulation time increases frame by frame"
    assert len(frames) == len(result) and [f.stage for f in frames] == result.stage, "on_frame saw every frame"
    assert (result.left_id, result.right_id, result.gripper_sensor_id) == ("cell/pad_left", "cell/pad_right",
                                                                            "cell/gripper")
    assert result.left_images.shape[1:] == (14, 6) and result.left_images.dtype == np.uint16
    np.testing.assert_array_equal(result.left_images.sum(axis=(1, 2)), result.left_sum)
    assert np.median(np.diff(result.time)) == pytest.approx(1 / 50, rel=0.05), "the default 50 frames/s"
    hold = result.stage_spans()[STAGES.index("hold")]
    assert hold[2] - hold[1] == pytest.approx(HOLD, abs=2 / 50)


def test_every_stage_has_a_frame_at_a_low_frame_rate(client, cell):
    """Stages shorter than a frame period (release takes ~10 ms) still show up: the stream covers every stage."""
    result = client.run_work_cycle(cell, "cell", "cube", frame_rate_hz=10, hold_time=0.1, timeout=120)
    assert [name for name, _, _ in result.stage_spans()] == list(STAGES), result.stage_spans()


def test_cube_is_lifted_and_put_back(cycle):
    result, _ = cycle
    z = result.object_position[:, 2]
    start = z[0]
    assert start == pytest.approx(TABLE_TOP + CUBE / 2, abs=1e-3)
    held = z[result.stage_mask("hold")]
    np.testing.assert_allclose(held - start, LIFT, atol=0.002, err_msg="lifted by lift_height while holding")
    assert z[-1] == pytest.approx(start, abs=0.002), "put back on the table"
    np.testing.assert_allclose(result.object_position[-1, :2], result.object_position[0, :2], atol=0.002)
    assert result.left_sum[-1] == result.right_sum[-1] == 0, "released"
    assert result.summary().slip == pytest.approx(0, abs=0.002)


def test_pads_agree_while_holding_at_the_setpoint(cycle):
    result, _ = cycle
    hold = result.stage_mask("hold")
    left, right = result.left_sum[hold], result.right_sum[hold]
    assert (left > 0).all() and (right > 0).all()
    assert result.summary().hold_mismatch <= 0.02, (left, right)
    assert np.mean((left + right) / 2) == pytest.approx(SETPOINT, rel=0.1), "force control holds the set-point"


def test_bad_requests_name_the_field(client, cell):
    cases = [
        (dict(gripper_id="nope"), None, ["gripper_id", "nope"]),
        (dict(object_id="nope"), None, ["object_id", "nope"]),
        (dict(coverage=1.5), IA, ["coverage", "1.5"]),
        (dict(lift_height=-0.01), IA, ["lift_height", "-0.01"]),
        (dict(coverage=0.15), IA, ["tactile_setpoint", "60000"]),  # 2 rows covered: full scale 49140
    ]
    for overrides, code, fragments in cases:
        args = dict(gripper_id="cell", object_id="cube", hold_time=0.1)
        args.update(overrides)
        gripper, obj = args.pop("gripper_id"), args.pop("object_id")
        with pytest.raises(graspsim.GraspsimError) as info:
            client.run_work_cycle(cell, gripper, obj, timeout=30, **args)
        err = info.value
        expected = code or (grpc.StatusCode.NOT_FOUND, IA)
        assert err.code in (expected if isinstance(expected, tuple) else (expected,)), err
        for fragment in fragments:
            assert fragment in err.message, f"{overrides}: message does not name {fragment!r}: {err}"
    assert_rejected(client, cell, IA, ["coverage"],
                    lambda: client.run_work_cycle(cell, "cell", "cube", coverage=1.5, timeout=30))
    with pytest.raises(graspsim.GraspsimError) as info:
        client.run_work_cycle("no-such-scene", "cell", "cube", timeout=30)
    assert info.value.code == grpc.StatusCode.NOT_FOUND and "scene_id" in info.value.message, info.value


def test_batched_frames_equal_one_frame_per_message(client, cell):
    """max_frames_per_message only changes how frames travel: the raw stream with one frame per message and the
    client's batched one (up to 64 per message) carry the same frames, bit for bit (the cycle is deterministic),
    on two scenes built alike."""
    from graspsim.v1 import tactile_pb2
    twin = client.create_scene("test_work_cycle twin").id
    try:
        client.add_object(twin, "table", builtin="table")
        client.add_object(twin, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
        client.add_robot(twin, "cell", builtin="schunk_pg70_on_z_axis", base_pose=[0, 0, BASE_Z, 1, 0, 0, 0])
        # A frame every 1 ms step: each 1/60 s chunk the server simulates at once yields ~17 frames, so batches form
        # however fast this reader is.
        request = dict(gripper_id="cell", object_id="cube", hold_time=0.2, lift_height=LIFT, frame_rate_hz=1000)
        singles = list(client.tactile_stub.RunWorkCycle(
            tactile_pb2.RunWorkCycleRequest(scene_id=cell, **request), timeout=120))
        assert all(len(m.following) == 0 for m in singles), "0 means one frame per message"
        with pytest.raises(grpc.RpcError) as info:
            list(client.tactile_stub.RunWorkCycle(
                tactile_pb2.RunWorkCycleRequest(scene_id=twin, max_frames_per_message=65, **request), timeout=30))
        assert info.value.code() == IA and "max_frames_per_message: 65" in info.value.details(), info.value
        batched = list(client.tactile_stub.RunWorkCycle(
            tactile_pb2.RunWorkCycleRequest(scene_id=twin, max_frames_per_message=64, **request), timeout=120))
    finally:
        client.delete_scene(twin)
    assert any(len(m.following) > 0 for m in batched), "frames simulated together travel together"
    flat = [part for m in batched for part in (m, *m.following)]
    for m in batched:
        m.ClearField("following")  # the leading frame of each message, on its own
    assert len(flat) == len(singles) > 20
    assert [m.SerializeToString() for m in flat] == [m.SerializeToString() for m in singles]
