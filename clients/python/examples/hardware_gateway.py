#!/usr/bin/env python3
"""The hardware gateway without hardware: emulated grippers (a Robotiq 2F-85 on Modbus TCP and a Schunk PG70 on
SMP, graspsim-emulator) behind a graspsim-gateway process, driven through the server like real ones: list them,
move, a refused command, e-stop, then a PG70 move beside its simulated twin with the surprise between them.

    python3 hardware_gateway.py --server 127.0.0.1:50051
"""
import argparse
import sys
import time

import numpy as np

import graspsim
from graspsim.testing.gateway_rig import GatewayRig, find_bin_dir


def wait_stopped(client, device_id, timeout=10.0):
    deadline = time.monotonic() + timeout
    reading = client.send_command(device_id, read=True).reading
    while reading.moving and time.monotonic() < deadline:
        time.sleep(0.02)
        reading = client.send_command(device_id, read=True).reading
    return reading


def demo(client: graspsim.Client, server: str) -> None:
    print("\nhardware gateway (graspsim-gateway serving emulated grippers: Robotiq 2F-85 on Modbus TCP, PG70 on SMP):")
    try:
        find_bin_dir()
    except FileNotFoundError as err:
        print(f"  skipped: {err}")
        return
    with GatewayRig(server, kinds=["robotiq-tcp", "pg70"], name="demo") as rig:
        for device in rig.wait_for_devices(client):
            print(f"  {device.id}: {device.kind} on {device.link}, open {1000 * device.last_reading.opening:.1f} mm,"
                  f" force {device.limits.min_force:g}..{device.limits.max_force:g} N")
        start = time.perf_counter()
        client.send_command("robotiq-tcp", move=(0.030, 0.10, 60))
        roundtrip_ms = 1000 * (time.perf_counter() - start)
        reading = wait_stopped(client, "robotiq-tcp")
        print(f"  robotiq-tcp moved to {1000 * reading.opening:.1f} mm (command round trip {roundtrip_ms:.1f} ms)")
        try:
            client.send_command("robotiq-tcp", move=(0.030, 0.10, 900))
        except graspsim.GraspsimError as err:
            print(f"  refused: {err.code.name}: {err.message}")
        stopped = client.emergency_stop()
        print(f"  e-stop: {', '.join(stopped.stopped)} stopped; moves refused until initialize")
        for device in stopped.stopped:
            client.send_command(device, initialize=True, timeout=10)

        scene_id = client.create_scene("gateway-twin").id
        try:
            client.add_robot(scene_id, "twin", builtin="schunk_pg70")
            client.send_command("pg70", move=(0.065, 0.06, 60))
            wait_stopped(client, "pg70")
            result = client.predict_action("pg70", scene_id, "twin", 0.020, 0.040, 80, rate_hz=20)
        finally:
            client.delete_scene(scene_id)
        gap = np.abs(result.predicted_opening - result.measured_opening).max()
        moving = result.measured_current > 0
        print(f"  PG70 65 -> 20 mm beside its simulated twin: {len(result.time)} samples over {result.time[-1]:.2f} s;"
              f" openings within {1000 * gap:.1f} mm; current measured {result.measured_current[moving].mean() if moving.any() else 0:.2f} A,"
              f" predicted {result.predicted_current.mean():.2f} A; surprise peak {result.surprise.max():.3f},"
              f" at the end {result.surprise[-1]:.3f}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051", help="host:port of graspsim-server")
    args = parser.parse_args(argv)
    with graspsim.connect(args.server) as client:
        demo(client, args.server)
    return 0


if __name__ == "__main__":
    sys.exit(main())
