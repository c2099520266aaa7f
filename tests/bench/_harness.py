"""Shared by the benchmarks: a graspsim-server of their own, machine facts and load, percentiles and medians,
channels."""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import grpc
import numpy as np

REPO = Path(__file__).resolve().parents[2]
SERVER_BIN = Path(os.environ.get("GRASPSIM_SERVER", REPO / "build" / "bin" / "graspsim-server"))
START_TIMEOUT_S = 30.0
STOP_TIMEOUT_S = 30.0


def log(*parts) -> None:
    print(*parts, file=sys.stderr, flush=True)


class Server:
    """One graspsim-server on a free port; a context manager that stops it with SIGTERM and checks exit 0.

    It listens on port 0 and we read the port it chose from its log line, so two runs never race for a port.
    """

    def __init__(self, *flags: str):
        self.log_path = Path(tempfile.mkstemp(prefix="graspsim-bench-", suffix=".log")[1])
        # Scenes and grasp sets go to a directory of this run, never the user's store (a benchmark may pass its
        # own --data-dir, e.g. to restart on the same data); removed when the server stops.
        self.data_dir = None
        if not any(f.startswith("--data-dir") for f in flags):
            self.data_dir = tempfile.mkdtemp(prefix="graspsim-bench-data-")
            flags = (f"--data-dir={self.data_dir}", *flags)
        with open(self.log_path, "wb") as out:
            self.process = subprocess.Popen([str(SERVER_BIN), "--listen=127.0.0.1:0", "--http-listen=off",
                                             "--log-level=info", *flags], stdout=out, stderr=subprocess.STDOUT)
        self.flags = flags
        self.address = f"127.0.0.1:{self._wait_port()}"
        self.exit_code = None

    def _wait_port(self) -> int:
        deadline = time.monotonic() + START_TIMEOUT_S
        while time.monotonic() < deadline:
            found = re.search(r"msg=listening .*port=(\d+)", self.log_path.read_text(errors="replace"))
            if found:
                return int(found.group(1))
            if self.process.poll() is not None:
                break
            time.sleep(0.05)
        self.process.kill()
        self.process.wait()
        tail = self.log_tail()
        self.log_path.unlink()
        raise RuntimeError(f"graspsim-server {self.flags} did not start:\n{tail}")

    def handler_seconds(self, method: str):
        """Time (s) the server spent in each handler of method, in call order, from its debug log (the server
        must run with --log-level=debug): where a call's time goes, server code or transport and client."""
        text = self.log_path.read_text(errors="replace")
        return [float(ms) / 1e3 for ms in re.findall(rf"msg=request method={method} .* ms=([\d.]+)", text)]

    def log_tail(self, lines: int = 20) -> str:
        return "\n".join(self.log_path.read_text(errors="replace").splitlines()[-lines:])

    def stop(self) -> int:
        if self.exit_code is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.exit_code = self.process.wait(STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.exit_code = self.process.wait()
                log(f"graspsim-server did not exit within {STOP_TIMEOUT_S} s of SIGTERM; killed")
            if self.exit_code != 0:
                log(f"graspsim-server exited with {self.exit_code} after SIGTERM (log kept: {self.log_path}):\n"
                    f"{self.log_tail()}")
            else:
                self.log_path.unlink()
            if self.data_dir:
                shutil.rmtree(self.data_dir, ignore_errors=True)
        return self.exit_code

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()


def channel(address: str, *extra_options) -> grpc.Channel:
    """A channel on its own TCP connection: grpc-python otherwise shares one connection between channels with
    equal options, and separate clients (threads standing for viewers, processes) would not be separate."""
    options = [("grpc.use_local_subchannel_pool", 1), ("grpc.max_receive_message_length", 256 << 20),
               *extra_options]
    ch = grpc.insecure_channel(address, options=options)
    grpc.channel_ready_future(ch).result(timeout=10)
    return ch


def ms_stats(prefix: str, seconds) -> dict:
    """p50, p99 and max (ms, rounded to µs) of durations in s, and how many exceeded 10 ms: a rare stall hides
    below p99 but a viewer or a control loop still feels it."""
    ms = np.asarray(seconds, dtype=np.float64) * 1e3
    return {f"{prefix}_ms_p50": round(float(np.percentile(ms, 50)), 3),
            f"{prefix}_ms_p99": round(float(np.percentile(ms, 99)), 3),
            f"{prefix}_ms_max": round(float(ms.max()), 3),
            f"{prefix}_over_10ms": int((ms > 10).sum())}


def load_avg_1m() -> float:
    """The machine's 1-minute load average, rounded: wall-clock figures move with it, so benches report it."""
    return round(os.getloadavg()[0], 2)


def median_spread(key: str, values, digits: int = 0) -> dict:
    """{key: median, key_min, key_max} of repeated measurements (the protocol: medians of >= 5 with their
    spread), rounded to `digits` (0: integers)."""
    def r(x):
        return round(float(x), digits) if digits else int(round(float(x)))
    return {key: r(np.median(values)), f"{key}_min": r(min(values)), f"{key}_max": r(max(values))}


def sleep_until(t: float) -> None:
    delay = t - time.perf_counter()
    if delay > 0:
        time.sleep(delay)


def process_cpu_s(pid: int) -> float:
    """User + system CPU time (s) a process has used so far, from /proc (10 ms ticks): on a shared machine it moves
    far less with the other load than wall time does."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def machine() -> dict:
    model = "unknown"
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    return {"nproc": len(os.sched_getaffinity(0)), "cpu": model}


def commit() -> dict:
    """The commit, and whether the working tree had uncommitted changes (then the figures are of HEAD + them)."""
    def git(*args):
        return subprocess.run(["git", "-C", str(REPO), *args], capture_output=True, text=True).stdout.strip()
    return {"commit": git("rev-parse", "--short", "HEAD") or "unknown",
            "tree_dirty": bool(git("status", "--porcelain", "--untracked-files=no"))}
