"""A hardware gateway session recorded beside its twin (issue 25, docs/recording.md): PredictAction on a scene
being recorded appends its request on "/graspsim/gateway/action" (graspsim.v1.PredictActionRequest) and every
sample it streams on "/graspsim/gateway/prediction" (graspsim.v1.PredictionSample). Real processes, as in
test_gateway.py: graspsim-server, graspsim-gateway and the PG70 emulator (graspsim.testing.gateway_rig). The file
is read with classes built from the schemas it embeds (mcap-protobuf-support), not with this client's own.
"""
import math
import struct

from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.unknown_fields import UnknownFieldSet
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

import graspsim
from graspsim.testing.gateway_rig import GatewayRig
from graspsim.v1 import gateway_pb2

from _support import wait_stopped

ACTION, PREDICTION = "/graspsim/gateway/action", "/graspsim/gateway/prediction"


def same_value(a, b) -> bool:
    """Exact: floats bit for bit (a NaN equals a NaN, 0.0 differs from -0.0)."""
    if isinstance(a, float) or isinstance(b, float):
        return struct.pack("<d", a) == struct.pack("<d", b)
    return a == b


def assert_same_fields(decoded, expected, where: str) -> None:
    """`decoded` (a class built from the file's schema) has the fields of `expected` (this client's class) by name,
    number and type, each set alike and equal, recursively; and nothing the schema does not know."""
    assert decoded.DESCRIPTOR.full_name == expected.DESCRIPTOR.full_name, where
    assert len(UnknownFieldSet(decoded)) == 0, f"{where}: fields the embedded schema lacks"
    theirs = {f.name: (f.number, f.type, f.label) for f in decoded.DESCRIPTOR.fields}
    ours = {f.name: (f.number, f.type, f.label) for f in expected.DESCRIPTOR.fields}
    assert theirs == ours, f"{where}: the embedded schema differs from graspsim.v1's"
    for field in expected.DESCRIPTOR.fields:
        at = f"{where}.{field.name}"
        got, want = getattr(decoded, field.name), getattr(expected, field.name)
        if field.label == FieldDescriptor.LABEL_REPEATED:
            assert len(got) == len(want), at
            for i, (g, w) in enumerate(zip(got, want)):
                if field.type == FieldDescriptor.TYPE_MESSAGE:
                    assert_same_fields(g, w, f"{at}[{i}]")
                else:
                    assert same_value(g, w), (at, i, g, w)
        elif field.type == FieldDescriptor.TYPE_MESSAGE:
            assert decoded.HasField(field.name) == expected.HasField(field.name), at
            assert_same_fields(got, want, at)
        else:
            assert same_value(got, want), (at, got, want)


def test_a_predicted_action_is_recorded_beside_its_twin(start_server, tmp_path):
    """Start a recording of the twin's scene, run PredictAction to completion, stop: the file holds one action
    message equal to the request sent and the prediction samples equal, field by field and in order, to those the
    client received."""
    recordings = tmp_path / "recordings"
    proc = start_server(f"--recording-dir={recordings}")
    with graspsim.connect(proc.address) as client, \
            GatewayRig(proc.address, kinds=["pg70"], name="recorded", log_path=tmp_path / "gateway.log") as rig:
        rig.wait_for_devices(client)
        scene_id = client.create_scene("gateway twin").id
        client.add_robot(scene_id, "pg70_twin", builtin="schunk_pg70")
        client.send_command("pg70", move=(0.065, 0.06, 60))
        assert not wait_stopped(client, "pg70").moving
        request = gateway_pb2.PredictActionRequest(
            device_id="pg70", scene_id=scene_id, gripper_id="pg70_twin",
            move=gateway_pb2.Move(opening=0.025, speed=0.04, force=80), timeout=10, rate_hz=20)
        info = client.start_recording(scene_id, name="gateway.mcap")
        call = client.gateway_stub.PredictAction(request, timeout=60)
        try:
            samples = list(call)
        finally:
            call.cancel()
        stopped = client.stop_recording(scene_id)
    assert len(samples) >= 5 and samples[-1].done and not any(s.done for s in samples[:-1])
    assert [s.time for s in samples] == sorted(s.time for s in samples) and samples[0].time == 0
    assert math.isclose(samples[-1].measured.opening, 0.025, abs_tol=1e-3), "the action ran to its end"
    assert stopped.path == info.path and stopped.frames >= 1

    actions, predictions = [], []
    with open(stopped.path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        channels = {c.topic: c for c in reader.get_summary().channels.values()}
        schemas = reader.get_summary().schemas
        for topic, cls in ((ACTION, gateway_pb2.PredictActionRequest), (PREDICTION, gateway_pb2.PredictionSample)):
            assert channels[topic].message_encoding == "protobuf", topic
            schema = schemas[channels[topic].schema_id]
            assert (schema.name, schema.encoding) == (cls.DESCRIPTOR.full_name, "protobuf"), topic
        for _, channel, message, decoded in reader.iter_decoded_messages(topics=[ACTION, PREDICTION],
                                                                         log_time_order=False):
            (actions if channel.topic == ACTION else predictions).append((message, decoded))
    assert len(actions) == 1, len(actions)
    assert_same_fields(actions[0][1], request, "action")
    assert actions[0][0].data == request.SerializeToString(deterministic=True)
    assert len(predictions) == len(samples), (len(predictions), len(samples))
    for i, ((_, decoded), sample) in enumerate(zip(predictions, samples)):
        assert_same_fields(decoded, sample, f"prediction[{i}]")
    log_times = [m.log_time for m, _ in predictions]
    assert log_times == sorted(log_times) and actions[0][0].log_time <= log_times[0]
