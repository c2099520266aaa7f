"""Recordings read by other tools' code in Node (issue 25, docs/recording.md): @mcap/core + protobufjs read a
recorded work cycle, and @foxglove/ws-protocol subscribes to the server's live Foxglove endpoint. The scripts are
in tests/node, installed into build/node-tests by `make node-tests`; without node the tests skip.

Shared pieces (the work-cycle recording): _recording_support.py.
"""
import json
import shutil
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import graspsim

from _recording_support import work_cycle_recording
from conftest import REPO_ROOT, free_port

NODE = shutil.which("node")
NODE_TESTS = REPO_ROOT / "build" / "node-tests"


@pytest.fixture(scope="module")
def recorded(server, tmp_path_factory):
    """The work cycle recorded once on the shared server (_recording_support.work_cycle_recording)."""
    return work_cycle_recording(server, tmp_path_factory)


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
