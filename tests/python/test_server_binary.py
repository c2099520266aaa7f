"""The server binary itself: --help, flags and config files, reflection, and start-up errors."""
import re
import subprocess

import grpc
from grpc_reflection.v1alpha import reflection_pb2, reflection_pb2_grpc

import graspsim
from conftest import server_binary

API_SERVICES = {"graspsim.v1.SceneService", "graspsim.v1.PerceptionService", "graspsim.v1.GraspService",
                "graspsim.v1.TactileService", "graspsim.v1.GatewayService"}


def run_binary(*args):
    return subprocess.run([str(server_binary()), *args], capture_output=True, text=True, timeout=30)


def test_help_documents_every_flag_with_its_default():
    result = run_binary("--help")
    assert result.returncode == 0
    flags = dict(re.findall(r"^\s+--([a-z-]+)=(\S*)", result.stdout, re.MULTILINE))
    for flag in ("listen", "config", "log-level", "http-listen", "max-message-bytes", "max-scenes",
                 "max-bodies-per-scene", "max-triangles-per-mesh", "max-upload-bytes", "max-scene-file-bytes",
                 "watch-max-rate-hz", "drain-timeout-s"):
        assert flag in flags, f"--{flag} missing from --help:\n{result.stdout}"
    assert flags["listen"] == "127.0.0.1:50051" and flags["http-listen"] == "127.0.0.1:8080"


def test_bad_flags_exit_2_naming_the_flag_and_value():
    for args, fragment in ((["--max-scenes=zero"], "--max-scenes: 'zero'"),
                           (["--no-such-flag=1"], "--no-such-flag"),
                           (["--log-level=loud"], "--log-level: 'loud'"),
                           (["--config=/nonexistent/graspsim.conf"], "/nonexistent/graspsim.conf")):
        result = run_binary(*args)
        assert result.returncode == 2 and fragment in result.stderr, (args, result.stderr)


def test_config_file_sets_flags_and_the_command_line_wins(start_server, tmp_path):
    config = tmp_path / "graspsim.conf"
    config.write_text("# limits for this test\nmax-scenes = 1\nmax-bodies-per-scene = 1\n")
    proc = start_server(f"--config={config}", "--max-bodies-per-scene=2")
    with graspsim.connect(proc.address) as client:
        scene = client.create_scene("only").id
        try:
            client.create_scene("second")
            raise AssertionError("max-scenes = 1 from the config file was not applied")
        except graspsim.GraspsimError as err:
            assert err.code == grpc.StatusCode.RESOURCE_EXHAUSTED
        client.add_object(scene, "a", sphere=0.01, mass=0.01)
        client.add_object(scene, "b", sphere=0.01, mass=0.01)  # 2 bodies allowed: the command line won


def test_reflection_lists_the_api_and_health(server):
    with grpc.insecure_channel(server.address) as channel:
        stub = reflection_pb2_grpc.ServerReflectionStub(channel)
        request = reflection_pb2.ServerReflectionRequest(list_services="")
        response = next(stub.ServerReflectionInfo(iter([request]), timeout=10))
    names = {service.name for service in response.list_services_response.service}
    assert API_SERVICES | {"grpc.health.v1.Health"} <= names


def test_port_in_use_fails_to_start_with_a_clear_message(server):
    result = run_binary(f"--listen={server.address}", "--http-listen=off")
    assert result.returncode == 1 and server.address in result.stderr
