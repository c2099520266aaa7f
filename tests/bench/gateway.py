"""gateway: the hardware gateway's command round trip and its watchdog, with real processes on loopback:
graspsim-server, graspsim-gateway and three graspsim-emulator processes (Robotiq 2F-85 on Modbus TCP, Robotiq on
Modbus RTU over a pty pair, PG70 on SMP over a socketpair).

cmd_roundtrip: SendCommand(read) from this client → server → gateway → emulator (one Modbus or SMP exchange) and
back, ROUNDS per device, round-robin over the devices; move_roundtrip the same for moves (the gateway sends the
move, then reads the device once). gateway_ms is the part the gateway spent in the driver.
watchdog_stop: the server is frozen (SIGSTOP) while two grippers close slowly; the time from the freeze to the
moment the gateway's stop of both was acknowledged by the devices (the gateway's "devices stopped" log line
has its Unix time), over STALLS trials. The watchdog limit is 200 ms of silence; the server heartbeats every
50 ms, so the figure lies between 150 ms and 200 ms plus the watchdog's 10 ms poll and the stop exchanges.
"""
import signal
import statistics
import time

import graspsim
from graspsim.testing.gateway_rig import GatewayRig

from _harness import Server, log, ms_stats

ROUNDS = 300
MOVES = 100
STALLS = 5
WATCHDOG_MS = 200


def roundtrips(client, devices, rounds, command):
    total, device_s = [], []
    for i in range(rounds):
        for device in devices:
            start = time.perf_counter()
            result = client.send_command(device, **command(i))
            total.append(time.perf_counter() - start)
            device_s.append(result.gateway_seconds)
    return total, device_s


def run():
    with Server("--grasp-data-dir=off") as server, graspsim.connect(server.address) as client, \
            GatewayRig(server.address, name="bench", gateway_flags=[f"--watchdog-ms={WATCHDOG_MS}"]) as rig:
        devices = [d.id for d in rig.wait_for_devices(client)]
        figures = {"devices": len(devices), "rounds_per_device": ROUNDS}
        total, device_s = roundtrips(client, devices, ROUNDS, lambda i: {"read": True})
        figures.update(ms_stats("cmd_roundtrip", total))
        figures.update(ms_stats("cmd_gateway", device_s))
        for device in devices:  # per link: TCP, RTU over a pty, SMP over a socketpair
            per, _ = roundtrips(client, [device], ROUNDS // 3, lambda i: {"read": True})
            figures[f"cmd_roundtrip_ms_p50_{device.replace('-', '_')}"] = ms_stats("x", per)["x_ms_p50"]
        moves, _ = roundtrips(client, devices, MOVES,
                              lambda i: {"move": (0.040 if i % 2 else 0.045, 0.05, 60)})
        figures.update(ms_stats("move_roundtrip", moves))
        log(f"gateway: round trips p50 {figures['cmd_roundtrip_ms_p50']} ms")

        stops, silent, stop_exchange = [], [], []
        for trial in range(STALLS):
            for device in ("robotiq-tcp", "pg70"):
                client.send_command(device, move=(0.060, 0.06, 60))
            time.sleep(1.0)
            for device in ("robotiq-tcp", "pg70"):
                client.send_command(device, move=(0.0, 0.020, 60))
            time.sleep(0.1)
            before = len(rig.gateway_events())
            frozen_at = time.time()
            server.process.send_signal(signal.SIGSTOP)
            time.sleep(0.6)
            server.process.send_signal(signal.SIGCONT)
            time.sleep(0.2)
            events = [e for e in rig.gateway_events()[before:] if e["why"].startswith("watchdog")]
            if len(events) != 1:
                raise RuntimeError(f"stall {trial}: expected one watchdog stop, got {events}:\n{rig.log_tail()}")
            stops.append((float(events[0]["unix"]) - frozen_at) * 1e3)
            silent.append(float(events[0]["silent_ms"]))
            stop_exchange.append(float(events[0]["stop_ms"]))
            for device in ("robotiq-tcp", "pg70"):
                if client.send_command(device, read=True).reading.moving:
                    raise RuntimeError(f"stall {trial}: {device} still moving after the watchdog")
        figures.update({"watchdog_limit_ms": WATCHDOG_MS,
                        "watchdog_stop_ms": round(statistics.median(stops), 1),
                        "watchdog_stop_ms_max": round(max(stops), 1),
                        "watchdog_silent_ms_median": round(statistics.median(silent), 1),
                        "watchdog_stop_exchange_ms_median": round(statistics.median(stop_exchange), 2),
                        "stalls": STALLS})
    return figures, server.exit_code
