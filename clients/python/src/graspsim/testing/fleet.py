"""A fleet on one machine: n graspsim-server replicas on loopback, each with its own data dir, behind HAProxy
with deploy/haproxy/graspsim-fleet.cfg (docs/scaling.md). Used by tests/python/test_fleet.py and
`tests/bench/run fleet`; also a way to try a fleet by hand:

    with Fleet(server="build/bin/graspsim-server", config="deploy/haproxy/graspsim-fleet.cfg",
               health_probe="build/tools/bin/grpc-health-probe", workdir="/tmp/fleet") as fleet:
        client = graspsim.connect(fleet.address, fleet=True)
"""
from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import time
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence

from graspsim._health import serving

def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


def _wait(predicate: Callable[[], object], timeout: float, what: str, process: Optional[subprocess.Popen[Any]] = None,
          log: Optional[Path] = None) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if process is not None and process.poll() is not None:
            tail = log.read_text(errors="replace")[-3000:] if log else ""
            raise RuntimeError(f"{what}: exited with {process.returncode}\n{tail}")
        if predicate():
            return
        time.sleep(0.05)
    raise TimeoutError(f"{what}: not ready within {timeout:g} s")


class Replica:
    """One graspsim-server: fixed gRPC and HTTP ports and data dir, so that a restart brings its scenes back."""

    def __init__(self, name: str, server: str, data_dir: Path, flags: Sequence[str] = ()):
        self.name, self.server, self.data_dir, self.flags = name, server, Path(data_dir), list(flags)
        self.port, self.http_port = free_port(), free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.http_address = f"127.0.0.1:{self.http_port}"
        self.log_path = self.data_dir.parent / f"{name}.log"
        self.process: Optional[subprocess.Popen[bytes]] = None

    def start(self, timeout: float = 60.0) -> None:
        self.data_dir.mkdir(parents=True, exist_ok=True)
        with open(self.log_path, "ab") as log:
            self.process = subprocess.Popen(
                [self.server, f"--listen={self.address}", f"--http-listen={self.http_address}",
                 f"--data-dir={self.data_dir}", *self.flags], stdout=log, stderr=subprocess.STDOUT)
        _wait(lambda: serving(self.address), timeout, f"replica {self.name}", self.process, self.log_path)

    def kill(self) -> None:
        """kill -9: no drain, no shutdown (the data dir is what survives)."""
        if self.process and self.process.poll() is None:
            self.process.kill()
            self.process.wait()

    def stop(self) -> None:
        if self.process and self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.kill()


class Fleet:
    """`replicas` servers and one HAProxy in front (`address`: its gRPC port, `http_address`: its HTTP port).
    The config may name more replicas than are started (GRASPSIM_REPLICA_<i> of the others then points at a
    closed port)."""

    def __init__(self, server: str, config: str, health_probe: str, workdir: str, replicas: int = 3,
                 server_flags: Sequence[str] = ()):
        self.workdir = Path(workdir)
        self.workdir.mkdir(parents=True, exist_ok=True)
        self.config = Path(config)
        self.health_probe = Path(health_probe)
        self.replicas: List[Replica] = [Replica(f"r{i}", server, self.workdir / f"r{i}-data", server_flags)
                                        for i in range(replicas)]
        self.port, self.http_port = free_port(), free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.http_address = f"127.0.0.1:{self.http_port}"
        self.balancer: Optional[subprocess.Popen[bytes]] = None

    def __enter__(self) -> Fleet:
        try:
            for replica in self.replicas:
                replica.start()
            self.start_balancer()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def environment(self, config_text: Optional[str] = None) -> Dict[str, str]:
        env = dict(os.environ, GRASPSIM_FLEET_GRPC=self.address, GRASPSIM_FLEET_HTTP=self.http_address,
                   GRASPSIM_HEALTH_CHECK=str(self.config.parent.resolve() / "grpc-health-check"),
                   GRASPSIM_HEALTH_PROBE_DIR=str(self.health_probe.parent.resolve()))
        named = set(re.findall(r"GRASPSIM_REPLICA_(\d+)", config_text or self.config.read_text()))
        for i in sorted(int(n) for n in named):
            replica = self.replicas[i] if i < len(self.replicas) else None
            env[f"GRASPSIM_REPLICA_{i}"] = replica.address if replica else f"127.0.0.1:{free_port()}"
            env[f"GRASPSIM_REPLICA_HTTP_{i}"] = replica.http_address if replica else f"127.0.0.1:{free_port()}"
        return env

    def start_balancer(self, config_text: Optional[str] = None, timeout: float = 30.0) -> None:
        """Starts HAProxy (stopping a running one first) with the config file, or with config_text instead."""
        self.stop_balancer()
        path = self.config
        if config_text is not None:
            path = self.workdir / "haproxy.cfg"
            path.write_text(config_text)
        check = subprocess.run(["haproxy", "-c", "-q", "-f", str(path)], env=self.environment(config_text),
                               capture_output=True, text=True)
        if check.returncode != 0:
            raise RuntimeError(f"haproxy -c {path}: {check.stdout}{check.stderr}")
        log = self.workdir / "haproxy.log"
        with open(log, "ab") as out:
            self.balancer = subprocess.Popen(["haproxy", "-db", "-f", str(path)], env=self.environment(config_text),
                                             stdout=out, stderr=subprocess.STDOUT)
        _wait(lambda: serving(self.address), timeout, "haproxy", self.balancer, log)

    def stop_balancer(self) -> None:
        if self.balancer and self.balancer.poll() is None:
            self.balancer.terminate()
            try:
                self.balancer.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.balancer.kill()
                self.balancer.wait()

    def add_replica(self, server_flags: Sequence[str] = ()) -> Replica:
        """Starts one more replica (not yet in any balancer config)."""
        base = self.replicas[0]
        replica = Replica(f"r{len(self.replicas)}", base.server, self.workdir / f"r{len(self.replicas)}-data",
                          server_flags or base.flags)
        replica.start()
        self.replicas.append(replica)
        return replica

    def close(self) -> None:
        self.stop_balancer()
        for replica in self.replicas:
            replica.stop()


def config_with_replicas(text: str, count: int) -> str:
    """The config with `count` replicas: each backend's server lines for r0..r2 extended (or cut) to count."""
    out = []
    for line in text.splitlines():
        match = re.match(r"(\s+server r)(\d+)( .*)", line)
        if not match:
            out.append(line)
            continue
        index = int(match.group(2))
        if index < count:
            out.append(line)
        if index == 2:  # the last template line: the added replicas follow it
            for extra in range(3, count):
                out.append(f"{match.group(1)}{extra}{match.group(3).replace('_2}', f'_{extra}}}')}")
    return "\n".join(out) + "\n"
