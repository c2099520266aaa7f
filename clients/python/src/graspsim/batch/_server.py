"""ServerActor: a Ray actor that runs a graspsim-server of its own (loopback, its own data directory) and a
graspsim.Client of it, and runs work items against it. ServerHost is the same without Ray (plain Python)."""
from __future__ import annotations

import atexit
import ctypes
import os
import re
import shutil
import signal
import socket
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Dict, Optional, Sequence, Tuple

import ray

import graspsim
from graspsim._health import serving

START_TIMEOUT_S = 60.0
STOP_TIMEOUT_S = 30.0


def server_binary(server: Optional[str] = None) -> str:
    """The graspsim-server to run: `server`, else $GRASPSIM_SERVER, else graspsim-server on the PATH."""
    path = server or os.environ.get("GRASPSIM_SERVER") or shutil.which("graspsim-server")
    if not path or not os.path.isfile(path):
        raise FileNotFoundError(f"graspsim-server not found ({path or 'not on the PATH'}): pass server=PATH or "
                                "set $GRASPSIM_SERVER")
    return str(path)


_SUPPORTS: Dict[Tuple[str, str], bool] = {}


def supports_flag(binary: str, flag: str) -> bool:
    """Whether the binary's --help lists `flag` (e.g. "--compute-threads")."""
    if (binary, flag) not in _SUPPORTS:
        text = subprocess.run([binary, "--help"], capture_output=True, text=True, timeout=30).stdout
        _SUPPORTS[binary, flag] = f"{flag}=" in text
    return _SUPPORTS[binary, flag]


_PRCTL: Optional[Callable[..., int]]
try:  # resolved here, not in the forked child (no dlopen between fork and exec in a process with threads)
    _PRCTL = ctypes.CDLL(None, use_errno=True).prctl
except (OSError, AttributeError):
    _PRCTL = None


def _die_with_parent() -> None:
    """In the child before exec: SIGTERM when the actor's process dies, even by SIGKILL (ray.kill)."""
    if _PRCTL is not None:
        _PRCTL(1, signal.SIGTERM)  # PR_SET_PDEATHSIG


class ServerHost:
    """Starts graspsim-server on 127.0.0.1 (port chosen by the server) with --http-listen=off, its scenes and
    grasp sets in data_dir (a temporary directory when None), --compute-threads=N (default 1 when the binary has
    the flag; given explicitly it is always passed) and `flags`; waits for SERVING. stop() removes the data dir
    unless keep_data (default: keep a data_dir that was given, remove a temporary one)."""

    def __init__(self, server: Optional[str] = None, compute_threads: Optional[int] = None,
                 data_dir: Optional[str] = None, flags: Sequence[str] = (), call_timeout: float = 3600.0,
                 keep_data: Optional[bool] = None) -> None:
        binary = server_binary(server)
        threads = compute_threads
        if threads is None and supports_flag(binary, "--compute-threads"):
            threads = 1
        self.compute_threads = threads
        self.process: Optional[subprocess.Popen[bytes]] = None
        self.client: Optional[graspsim.Client] = None
        self.owns_dir = not keep_data if keep_data is not None else data_dir is None
        self.data_dir = data_dir or tempfile.mkdtemp(prefix="graspsim-batch-")
        os.makedirs(self.data_dir, exist_ok=True)
        argv = [binary, "--listen=127.0.0.1:0", "--http-listen=off", f"--data-dir={self.data_dir}",
                f"--grasp-data-dir={self.data_dir}", *([f"--compute-threads={threads}"] if threads else []), *flags]
        self.log_path = Path(self.data_dir) / "server.log"
        try:
            with open(self.log_path, "ab") as log:
                self.process = subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT,
                                                preexec_fn=_die_with_parent)
        except (OSError, subprocess.SubprocessError):
            self.stop()  # removes a temporary data dir
            raise
        atexit.register(self.stop)
        self.address = f"127.0.0.1:{self._wait_serving()}"
        self.client = graspsim.connect(self.address, call_timeout=call_timeout)

    @property
    def _started(self) -> subprocess.Popen[bytes]:
        """The server process: set by __init__ (or __init__ raised), so never None on a constructed host."""
        assert self.process is not None
        return self.process

    def _wait_serving(self) -> int:
        deadline, port = time.monotonic() + START_TIMEOUT_S, None
        while time.monotonic() < deadline:
            if self._started.poll() is not None:
                break
            if port is None:
                found = re.search(r"msg=listening .*port=(\d+)", self.log_path.read_text(errors="replace"))
                port = int(found.group(1)) if found else None
            if port is not None and self._serving(f"127.0.0.1:{port}", 1.0):
                return port
            time.sleep(0.05)
        tail = self.log_tail()
        self.stop()
        raise RuntimeError(f"graspsim-server did not start (exit {self._started.returncode}):\n{tail}")

    _serving = staticmethod(serving)

    def alive(self) -> bool:
        """The server process runs and answers its health check."""
        return self._started.poll() is None and self._serving(self.address, 5.0)

    def log_tail(self, lines: int = 20) -> str:
        try:
            return "\n".join(self.log_path.read_text(errors="replace").splitlines()[-lines:])
        except OSError:
            return ""

    def info(self) -> Dict[str, Any]:
        return {"node": socket.gethostname(), "pid": os.getpid(), "server_pid": self._started.pid,
                "address": self.address, "data_dir": self.data_dir, "compute_threads": self.compute_threads}

    def run(self, fn: Callable[..., Any], item: Any, *args: Any) -> Tuple[str, Any]:
        """("ok", fn(client, item, *args)); ("error", "Type: message") when fn raised and the server still
        serves; ("lost", why) when the server died under it (the caller retries elsewhere)."""
        try:
            return "ok", fn(self.client, item, *args)
        except Exception as err:  # noqa: BLE001 - any failure of the work item is reported, not raised
            if not self.alive():
                return "lost", f"graspsim-server not serving (exit code {self._started.poll()}): {self.log_tail(5)}"
            return "error", f"{type(err).__name__}: {err}"

    def stop(self) -> Optional[int]:
        """SIGTERM, wait (SIGKILL after STOP_TIMEOUT_S); removes a temporary data dir. Returns the exit code."""
        if self.client is not None:
            self.client.close()
            self.client = None
        code = None
        if self.process is not None:
            if self.process.poll() is None:
                self.process.send_signal(signal.SIGTERM)
                try:
                    self.process.wait(STOP_TIMEOUT_S)
                except subprocess.TimeoutExpired:
                    self.process.kill()
                    self.process.wait()
            code = self.process.returncode
        if self.owns_dir:
            shutil.rmtree(self.data_dir, ignore_errors=True)
        return code

    def __del__(self) -> None:
        if "owns_dir" in self.__dict__:
            self.stop()


# max_restarts=0: a dead actor stays dead; the dispatcher (graspsim.batch._pool) starts a replacement itself.
ServerActor = ray.remote(num_cpus=1, max_restarts=0)(ServerHost)
