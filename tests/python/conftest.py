"""End-to-end fixtures: the real graspsim-server binary on a free port, and clients of it.

The binary is $GRASPSIM_SERVER, else <repo>/build/bin/graspsim-server. Each server is started with
--listen=127.0.0.1:PORT plus a test's flags, is ready once grpc.health.v1 answers SERVING, and must exit
with code 0 on SIGTERM.
"""
import os
import signal
import socket
import subprocess
import time
from pathlib import Path

import grpc
import pytest
from grpc_health.v1 import health_pb2, health_pb2_grpc

import graspsim

# No progress bars in the tests' output (the client's long calls show them by default): tqdm >= 4.66 reads this
# when it is first imported, later than here (graspsim imports it only for a bar); the examples and Ray workers the
# tests start inherit it.
os.environ.setdefault("TQDM_DISABLE", "1")

REPO_ROOT = Path(__file__).resolve().parents[2]
START_TIMEOUT_S = 30.0
STOP_TIMEOUT_S = 30.0


def server_binary() -> Path:
    path = Path(os.environ.get("GRASPSIM_SERVER", REPO_ROOT / "build" / "bin" / "graspsim-server"))
    if not path.is_file():
        pytest.fail(f"graspsim-server not found at {path}: build it (make) or set GRASPSIM_SERVER", pytrace=False)
    return path


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class ServerProcess:
    """One running graspsim-server; its stdout and stderr go to log_path."""

    def __init__(self, flags, log_dir: Path):
        self.flags = list(flags)
        self.port = free_port()
        self.address = f"127.0.0.1:{self.port}"
        # Each server gets its own HTTP port too, so that several can run at once.
        self.http_port = free_port()
        self.http_url = f"http://127.0.0.1:{self.http_port}"
        self.log_path = log_dir / f"graspsim-server-{self.port}.log"
        with open(self.log_path, "wb") as log:
            # Grasp sets and scenes go to the test's own directories, never the user's (a test may pass its own
            # flags: a restart test passes the same --data-dir to the second server).
            data_dir = [] if any(f.startswith("--grasp-data-dir") for f in self.flags) else \
                [f"--grasp-data-dir={log_dir / f'grasps-{self.port}'}"]
            if not any(f.startswith("--data-dir") for f in self.flags):
                data_dir.append(f"--data-dir={log_dir / f'scenes-{self.port}'}")
            self.process = subprocess.Popen([str(server_binary()), f"--listen={self.address}",
                                             f"--http-listen=127.0.0.1:{self.http_port}", *data_dir, *self.flags],
                                            stdout=log, stderr=subprocess.STDOUT)
        self._wait_serving()

    def log_tail(self, lines: int = 30) -> str:
        return "\n".join(self.log_path.read_text(errors="replace").splitlines()[-lines:])

    def health(self, timeout: float = 5.0) -> str:
        """The health service's status name for the whole server ("" service), e.g. "SERVING"."""
        with grpc.insecure_channel(self.address) as channel:
            reply = health_pb2_grpc.HealthStub(channel).Check(health_pb2.HealthCheckRequest(service=""),
                                                              timeout=timeout)
        return health_pb2.HealthCheckResponse.ServingStatus.Name(reply.status)

    def _wait_serving(self) -> None:
        deadline = time.monotonic() + START_TIMEOUT_S
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                pytest.fail(f"graspsim-server {self.flags} exited with {self.process.returncode} at start:\n"
                            f"{self.log_tail()}", pytrace=False)
            try:
                if self.health(timeout=1.0) == "SERVING":
                    return
            except grpc.RpcError:
                pass
            time.sleep(0.1)
        self.process.kill()
        pytest.fail(f"graspsim-server {self.flags} not SERVING within {START_TIMEOUT_S} s:\n{self.log_tail()}",
                    pytrace=False)

    def stop(self) -> int:
        """SIGTERM, then the exit code (the process is killed if it does not exit in time)."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(timeout=STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
                pytest.fail(f"graspsim-server did not exit within {STOP_TIMEOUT_S} s of SIGTERM:\n{self.log_tail()}")
        return self.process.returncode


@pytest.fixture(scope="session")
def server(tmp_path_factory):
    """The shared default server. At the end of the session it must still be SERVING and exit 0 on SIGTERM."""
    proc = ServerProcess([], tmp_path_factory.mktemp("server"))
    yield proc
    try:
        assert proc.health() == "SERVING", f"server no longer SERVING after the session:\n{proc.log_tail()}"
    finally:
        code = proc.stop()
    assert code == 0, f"server exited with {code} on SIGTERM:\n{proc.log_tail()}"


@pytest.fixture
def start_server(tmp_path):
    """Factory: start_server("--max-scenes=3", ...) -> a ServerProcess of its own, stopped after the test."""
    started = []

    def start(*flags) -> ServerProcess:
        started.append(ServerProcess(flags, tmp_path))
        return started[-1]

    yield start
    for proc in started:
        code = proc.stop()
        assert code == 0, f"server {proc.flags} exited with {code} on SIGTERM:\n{proc.log_tail()}"


@pytest.fixture(scope="session")
def client(server):
    with graspsim.connect(server.address) as c:
        yield c


@pytest.fixture
def scene_id(client, request):
    """A fresh scene on the shared server, deleted after the test."""
    sid = client.create_scene(request.node.name[:128]).id
    yield sid
    try:
        client.delete_scene(sid)
    except graspsim.GraspsimError as err:
        assert err.code == grpc.StatusCode.NOT_FOUND, str(err)
