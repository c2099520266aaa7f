"""A bench of real processes for trying the hardware gateway without hardware: graspsim-emulator processes
(Robotiq 2F-85 on Modbus TCP and on Modbus RTU over a pseudo-terminal, a PG70 speaking SMP over a socketpair)
and one graspsim-gateway connected to a server. Used by `make demo`, tests/python/test_gateway.py and
tests/bench/gateway.py.

    with GatewayRig("127.0.0.1:50051", bin_dir) as rig:
        rig.wait_for_devices(client)
        client.send_command("pg70", move=(0.02, 0.05, 100))
"""
from __future__ import annotations

import os
import re
import socket
import subprocess
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING, Dict, List, Optional, Sequence

if TYPE_CHECKING:
    from graspsim._client import Client
    from graspsim._devices import Device

KINDS = ("robotiq-tcp", "robotiq-rtu", "pg70")


def find_bin_dir(hint: Optional[os.PathLike[str]] = None) -> Path:
    """Where graspsim-gateway and graspsim-emulator are: `hint`, $GRASPSIM_BIN_DIR, the directory of
    $GRASPSIM_SERVER, or <repo>/build/bin."""
    candidates = [hint, os.environ.get("GRASPSIM_BIN_DIR")]
    if os.environ.get("GRASPSIM_SERVER"):
        candidates.append(Path(os.environ["GRASPSIM_SERVER"]).parent)
    candidates.append(Path(__file__).resolve().parents[5] / "build" / "bin")  # this file is 5 levels below <repo>
    for candidate in candidates:
        if candidate and (Path(candidate) / "graspsim-gateway").is_file():
            return Path(candidate)
    raise FileNotFoundError("graspsim-gateway not found: build it (make) or set GRASPSIM_BIN_DIR")


class GatewayRig:
    """Emulators of `kinds` (device ids equal the kinds) and a gateway named `name` serving them to `server`.
    `gateway_flags` are added to the gateway's command line (e.g. "--watchdog-ms=100"). The gateway's stderr
    goes to `log_path` (a temporary file by default); gateway_events() parses its "devices stopped" lines."""

    def __init__(self, server: str, bin_dir: Optional[os.PathLike[str]] = None, kinds: Sequence[str] = KINDS,
                 name: str = "rig", gateway_flags: Sequence[str] = (), log_path: Optional[os.PathLike[str]] = None
                 ) -> None:
        self.bin_dir = find_bin_dir(bin_dir)
        self.server = server
        self.name = name
        self.kinds = list(kinds)
        self.emulators: Dict[str, subprocess.Popen[str]] = {}
        self.gateway: Optional[subprocess.Popen[bytes]] = None
        self.addresses: Dict[str, str] = {}
        self.log_path = Path(log_path or tempfile.mkstemp(prefix="graspsim-gateway-", suffix=".log")[1])
        self._gateway_flags = list(gateway_flags)
        try:
            device_flags: List[str] = []
            keep: List[socket.socket] = []
            for kind in self.kinds:
                if kind not in KINDS:
                    raise ValueError(f"kinds: '{kind}' is not one of {KINDS}")
                if kind == "pg70":
                    emulator_end, gateway_end = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
                    self._start_emulator(kind, ["pg70", f"--fd={emulator_end.fileno()}"], [emulator_end.fileno()])
                    emulator_end.close()
                    keep.append(gateway_end)
                    device_flags.append(f"--device=pg70=pg70-fd:{gateway_end.fileno()}")
                else:
                    address = self._start_emulator(kind, [kind], [])
                    device_flags.append(f"--device={kind}={kind}:{address}")
            self._device_flags = device_flags
            self._fds = keep
            self.start_gateway()
        except BaseException:
            self.stop()
            raise

    def _start_emulator(self, kind: str, args: List[str], fds: List[int]) -> str:
        process = subprocess.Popen([str(self.bin_dir / "graspsim-emulator"), *args], stdout=subprocess.PIPE,
                                   stderr=subprocess.DEVNULL, text=True, pass_fds=fds)
        self.emulators[kind] = process
        assert process.stdout is not None  # stdout=PIPE
        first = process.stdout.readline().split()  # "robotiq-tcp 127.0.0.1:PORT ...", "robotiq-rtu /dev/pts/N ..."
        if len(first) < 2:
            raise RuntimeError(f"graspsim-emulator {kind} did not start (exit code {process.poll()})")
        self.addresses[kind] = first[1]
        return first[1]

    def start_gateway(self) -> None:
        """(Re)starts the gateway process (the PG70's socketpair end is kept for restarts)."""
        with open(self.log_path, "ab") as log:
            self.gateway = subprocess.Popen(
                [str(self.bin_dir / "graspsim-gateway"), f"--server={self.server}", f"--name={self.name}",
                 *self._device_flags, *self._gateway_flags],
                stdout=log, stderr=subprocess.STDOUT, pass_fds=[f.fileno() for f in self._fds])

    def wait_for_devices(self, client: Client, timeout: float = 20.0) -> List[Device]:
        """Waits until the server lists every device of this rig with a first reading; returns them."""
        deadline = time.monotonic() + timeout
        while True:
            gateway = self.gateway
            assert gateway is not None  # started by __init__ (start_gateway restarts it)
            devices = [d for d in client.list_devices() if d.gateway == self.name]
            if len(devices) == len(self.kinds) and all(d.last_reading.device_id for d in devices):
                return devices
            if gateway.poll() is not None:
                raise RuntimeError(f"graspsim-gateway exited with {gateway.returncode}:\n{self.log_tail()}")
            if time.monotonic() > deadline:
                raise TimeoutError(f"devices of gateway '{self.name}' not registered within {timeout} s:\n"
                                   f"{self.log_tail()}")
            time.sleep(0.05)

    def log_tail(self, lines: int = 30) -> str:
        return "\n".join(self.log_path.read_text(errors="replace").splitlines()[-lines:])

    def gateway_events(self) -> List[Dict[str, str]]:
        """The gateway's "devices stopped" log lines as dicts (why, stopped, silent_ms, stop_ms, unix)."""
        events: List[Dict[str, str]] = []
        for line in self.log_path.read_text(errors="replace").splitlines():
            if 'msg="devices stopped"' not in line:
                continue
            fields = dict(re.findall(r'(\w+)=("[^"]*"|\S+)', line))
            events.append({key: value.strip('"') for key, value in fields.items()})
        return events

    def stop_gateway(self) -> int:
        if self.gateway is None or self.gateway.poll() is not None:
            return self.gateway.returncode if self.gateway else 0
        self.gateway.terminate()
        try:
            return self.gateway.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.gateway.kill()
            return self.gateway.wait()

    def stop(self) -> None:
        self.stop_gateway()
        for process in self.emulators.values():
            if process.poll() is None:
                process.terminate()
                try:
                    process.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait()
        for f in getattr(self, "_fds", []):
            f.close()

    def __enter__(self) -> "GatewayRig":
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
