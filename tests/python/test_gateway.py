"""The hardware gateway end to end, as real processes: graspsim-server, graspsim-gateway and graspsim-emulator
(Robotiq 2F-85 on Modbus TCP over loopback and on Modbus RTU over a pty pair, a PG70 on SMP over a socketpair).
Every command path goes client → server → gateway → emulator and back. Fault injection inside the emulators
(Modbus exceptions, lost and malformed answers) is covered in-process by tests/cpp/gateway/gateway_e2e_test.cpp."""
import math
import signal
import subprocess
import time

import grpc
import pytest

import graspsim
from graspsim.testing.gateway_rig import GatewayRig
from _support import expect_error, wait_stopped
from conftest import server_binary

KINDS = ["robotiq-tcp", "robotiq-rtu", "pg70"]
MAX_OPENING = {"robotiq-tcp": 0.085, "robotiq-rtu": 0.085, "pg70": 0.070}
SPEED = {"robotiq-tcp": 0.10, "robotiq-rtu": 0.10, "pg70": 0.06}  # m/s
RESOLUTION = 1e-3  # m: a Robotiq count is 0.33 mm, the PG70 reports floats; 1 mm covers both


@pytest.fixture(scope="module")
def rig(server, tmp_path_factory):
    with graspsim.connect(server.address) as client:
        with GatewayRig(server.address, name="pytest-rig",
                        log_path=tmp_path_factory.mktemp("gateway") / "gateway.log") as r:
            r.wait_for_devices(client)
            yield r


def test_devices_registered_with_limits_and_readings(client, rig):
    devices = {d.id: d for d in client.list_devices() if d.gateway == rig.name}
    assert sorted(devices) == sorted(KINDS)
    assert devices["robotiq-tcp"].kind == devices["robotiq-rtu"].kind == "robotiq_2f85"
    assert devices["pg70"].kind == "schunk_pg70"
    assert "modbus tcp 127.0.0.1" in devices["robotiq-tcp"].link
    assert "modbus rtu /dev/pts/" in devices["robotiq-rtu"].link
    for kind, device in devices.items():
        assert device.limits.max_opening == pytest.approx(MAX_OPENING[kind])
        assert device.last_reading.device_id == kind
        assert abs(device.last_reading.time - time.time()) < 60  # Unix time of the gateway's clock


@pytest.mark.parametrize("kind", KINDS)
def test_move_reaches_target_and_reports_reading(client, rig, kind):
    target = 0.030
    result = client.send_command(kind, move=(target, SPEED[kind], 60))
    assert result.ok and result.command_id > 0
    assert result.reading.device_id == kind
    final = wait_stopped(client, kind)
    assert not final.moving and not final.fault
    assert final.opening == pytest.approx(target, abs=RESOLUTION)
    # Back open, through velocity / max_force / move_to (the speed and force set last).
    assert client.send_command(kind, velocity=SPEED[kind]).ok
    assert client.send_command(kind, max_force=80).ok
    assert client.send_command(kind, move_to=0.060).ok
    assert wait_stopped(client, kind).opening == pytest.approx(0.060, abs=RESOLUTION)


@pytest.mark.parametrize("kind", KINDS)
def test_stop_halts_a_move_short_of_its_target(client, rig, kind):
    client.send_command(kind, move=(0.060, SPEED[kind], 60))
    start = wait_stopped(client, kind).opening
    client.send_command(kind, move=(0.0, 0.020, 60))  # ~3 s to close at 20 mm/s
    time.sleep(0.3)
    assert client.send_command(kind, stop=True).ok
    time.sleep(0.2)
    first = client.send_command(kind, read=True).reading
    time.sleep(0.3)
    second = client.send_command(kind, read=True).reading
    assert not second.moving
    assert second.opening == pytest.approx(first.opening, abs=RESOLUTION)  # it stays put
    assert 0.01 < second.opening < start - 0.002


@pytest.mark.parametrize("field,kwargs,fragment", [
    ("move.opening", dict(move=(0.2, 0.05, 60)), "move.opening: 0.2 m is outside the limits"),
    ("move.speed", dict(move=(0.03, 5.0, 60)), "move.speed: 5 m/s is outside the limits"),
    ("move.force", dict(move=(0.03, 0.05, 900)), "move.force: 900 N is outside the limits"),
    ("velocity", dict(velocity=-1.0), "velocity: -1 m/s is outside the limits"),
    ("max_force", dict(max_force=1e4), "max_force: 10000 N is outside the limits"),
])
def test_commands_outside_the_limits_are_refused_and_change_nothing(client, rig, field, kwargs, fragment):
    before = wait_stopped(client, "robotiq-tcp")
    with expect_error(grpc.StatusCode.INVALID_ARGUMENT, fragment, "robotiq-tcp"):
        client.send_command("robotiq-tcp", **kwargs)
    after = client.send_command("robotiq-tcp", read=True).reading
    assert not after.moving and after.opening == pytest.approx(before.opening, abs=1e-9)


def test_bad_requests(client, rig):
    with expect_error(grpc.StatusCode.NOT_FOUND, "no device 'nope'"):
        client.send_command("nope", stop=True)
    with expect_error(grpc.StatusCode.INVALID_ARGUMENT, "move.opening", "nan"):
        client.send_command("pg70", move=(math.nan, 0.05, 60))
    with expect_error(grpc.StatusCode.INVALID_ARGUMENT, "timeout"):
        client.send_command("pg70", read=True, timeout=-1)
    with pytest.raises(ValueError):
        client.send_command("pg70", stop=True, read=True)
    with expect_error(grpc.StatusCode.NOT_FOUND, "no device 'nope'"):
        client.emergency_stop("nope")


def test_emergency_stop_latches_until_initialize(client, rig):
    for kind in KINDS:
        client.send_command(kind, move=(0.0, 0.020, 60))
    time.sleep(0.2)
    response = client.emergency_stop()
    assert sorted(response.stopped) == sorted(KINDS) and not response.failed
    time.sleep(0.2)
    for kind in KINDS:
        reading = client.send_command(kind, read=True).reading
        assert reading.estopped and not reading.moving
        with expect_error(grpc.StatusCode.FAILED_PRECONDITION, "e-stopped", "initialize"):
            client.send_command(kind, move=(0.05, SPEED[kind], 60))
        assert client.send_command(kind, initialize=True, timeout=10).ok
        assert not client.send_command(kind, read=True).reading.estopped
        assert client.send_command(kind, move=(0.05, SPEED[kind], 60)).ok
        assert wait_stopped(client, kind).opening == pytest.approx(0.05, abs=RESOLUTION)


def test_predict_action_on_the_pg70(client, rig, scene_id):
    client.add_robot(scene_id, "pg70_twin", builtin="schunk_pg70")
    client.send_command("pg70", move=(0.065, 0.06, 60))
    wait_stopped(client, "pg70")
    samples = []
    result = client.predict_action("pg70", scene_id, "pg70_twin", 0.025, 0.04, 80, rate_hz=20,
                                   on_sample=samples.append)
    assert result.finished and len(result.time) >= 5 and len(samples) == len(result.time)
    assert list(result.time) == sorted(result.time) and result.time[0] == 0
    assert result.measured_opening[0] == pytest.approx(0.065, abs=RESOLUTION)
    assert result.predicted_opening[0] == pytest.approx(0.065, abs=RESOLUTION)  # same start state
    assert result.measured_opening[-1] == pytest.approx(0.025, abs=RESOLUTION)
    # Both close at 40 mm/s: halfway through, the twin is within a few mm of the real fingers.
    mid = len(result.time) // 2
    assert result.predicted_opening[mid] == pytest.approx(result.measured_opening[mid], abs=0.005)
    # The surprise is the documented normalised difference (device limits: 0.070 m, 3.5 A).
    for s in samples:
        expected = math.sqrt((((s.predicted.opening - s.measured.opening) / 0.070) ** 2 +
                              ((s.predicted.current - s.measured.current) / 3.5) ** 2) / 2)
        assert s.surprise == pytest.approx(expected, rel=1e-9, abs=1e-12)
    assert 0 <= result.surprise.max() < 1


def test_predict_action_refusals(client, rig, scene_id):
    with expect_error(grpc.StatusCode.NOT_FOUND, "gripper_id", "nope"):
        client.predict_action("pg70", scene_id, "nope", 0.03, 0.04, 80)
    with expect_error(grpc.StatusCode.NOT_FOUND, "device_id", "ghost"):
        client.predict_action("ghost", scene_id, "pg70_twin", 0.03, 0.04, 80)
    client.add_robot(scene_id, "pg70_twin", builtin="schunk_pg70")
    with expect_error(grpc.StatusCode.INVALID_ARGUMENT, "move.force: 900 N is outside the limits"):
        client.predict_action("pg70", scene_id, "pg70_twin", 0.03, 0.04, 900)


def _start_server(address, log):
    process = subprocess.Popen([str(server_binary()), f"--listen={address}", "--http-listen=off",
                                "--grasp-data-dir=off", "--data-dir=off"], stdout=log, stderr=subprocess.STDOUT)
    with grpc.insecure_channel(address) as channel:
        grpc.channel_ready_future(channel).result(timeout=30)
    return process


def test_watchdog_stops_the_hardware_when_the_server_stalls(start_server, tmp_path):
    own = start_server()
    with graspsim.connect(own.address) as client, \
            GatewayRig(own.address, kinds=["robotiq-tcp", "pg70"], name="watchdog",
                       gateway_flags=["--watchdog-ms=200"], log_path=tmp_path / "gateway.log") as rig:
        rig.wait_for_devices(client)
        for kind in ("robotiq-tcp", "pg70"):
            client.send_command(kind, move=(0.0, 0.020, 60))  # 3.5 s or more to close
        time.sleep(0.2)
        stalled_at = time.time()
        own.process.send_signal(signal.SIGSTOP)
        try:
            time.sleep(1.0)
        finally:
            own.process.send_signal(signal.SIGCONT)
        events = [e for e in rig.gateway_events() if e["why"].startswith("watchdog")]
        assert len(events) == 1, rig.log_tail()
        assert float(events[0]["silent_ms"]) > 200 and events[0]["stopped"] == "2"
        print(f"watchdog stop {1000 * (float(events[0]['unix']) - stalled_at):.0f} ms after the stall")
        # Stopped early: still far from closed, and still when read twice; then work resumes.
        time.sleep(0.2)
        for kind in ("robotiq-tcp", "pg70"):
            first = client.send_command(kind, read=True).reading
            time.sleep(0.2)
            second = client.send_command(kind, read=True).reading
            assert not second.moving and second.opening > 0.03
            assert second.opening == pytest.approx(first.opening, abs=RESOLUTION)
            assert client.send_command(kind, move=(0.03, 0.06, 60)).ok
            assert wait_stopped(client, kind).opening == pytest.approx(0.03, abs=RESOLUTION)


def test_gateway_reconnects_after_the_server_restarts(tmp_path):
    with open(tmp_path / "server.log", "wb") as log:
        from conftest import free_port
        address = f"127.0.0.1:{free_port()}"
        server = _start_server(address, log)
        rig = None
        try:
            rig = GatewayRig(address, kinds=["robotiq-rtu", "pg70"], name="reconnect",
                             gateway_flags=["--backoff-max-ms=500"], log_path=tmp_path / "gateway.log")
            with graspsim.connect(address) as client:
                rig.wait_for_devices(client)
                client.send_command("robotiq-rtu", move=(0.0, 0.020, 60))
            server.kill()  # the link drops: the gateway stops its devices at once
            server.wait()
            time.sleep(0.5)
            assert any(e["why"] == "the link to the server ended" for e in rig.gateway_events()), rig.log_tail()
            server = _start_server(address, log)
            with graspsim.connect(address) as client:
                rig.wait_for_devices(client)
                reading = client.send_command("robotiq-rtu", read=True).reading
                assert not reading.moving and reading.opening > 0.03  # stopped when the link dropped
                assert client.send_command("pg70", move=(0.02, 0.06, 60)).ok  # work resumes
                assert wait_stopped(client, "pg70").opening == pytest.approx(0.02, abs=RESOLUTION)
            assert rig.gateway.poll() is None
        finally:
            if rig:
                rig.stop()
            server.terminate()
            server.wait(timeout=30)


def test_a_second_gateway_cannot_take_a_registered_id(client, rig, server, tmp_path):
    with GatewayRig(server.address, kinds=["robotiq-tcp"], name="intruder", log_path=tmp_path / "gateway.log") as other:
        deadline = time.monotonic() + 10
        while "already registered" not in other.log_tail() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert "register_device.id: 'robotiq-tcp' is already registered by gateway 'pytest-rig'" in other.log_tail()
        assert [d.gateway for d in client.list_devices() if d.id == "robotiq-tcp"] == ["pytest-rig"]


def test_devices_leave_with_their_gateway_and_return_with_it(start_server, tmp_path):
    own = start_server()
    with graspsim.connect(own.address) as client, \
            GatewayRig(own.address, kinds=["robotiq-tcp"], name="restarted", log_path=tmp_path / "gateway.log") as rig:
        rig.wait_for_devices(client)
        rig.gateway.kill()  # no goodbye: the server notices the broken stream
        rig.gateway.wait()
        deadline = time.monotonic() + 10
        while any(d.gateway == "restarted" for d in client.list_devices()) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(d.gateway == "restarted" for d in client.list_devices())
        with expect_error(grpc.StatusCode.NOT_FOUND, "no device 'robotiq-tcp'"):
            client.send_command("robotiq-tcp", read=True)
        rig.start_gateway()
        rig.wait_for_devices(client)
        assert client.send_command("robotiq-tcp", move=(0.04, 0.1, 60)).ok
        assert wait_stopped(client, "robotiq-tcp").opening == pytest.approx(0.04, abs=RESOLUTION)
