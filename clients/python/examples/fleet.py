"""A fleet on this machine: three graspsim-server replicas behind HAProxy (deploy/haproxy/graspsim-fleet.cfg),
scenes routed by their id, one replica killed and restarted, a fourth added and the scenes rebalanced onto it.

    python fleet.py --server-binary build/bin/graspsim-server --health-probe build/tools/bin/grpc-health-probe

Needs haproxy (Debian package) and grpc-health-probe (make go-tools). docs/scaling.md explains the design.
"""
import argparse
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import graspsim
from graspsim.fleet import rebalance
from graspsim.testing.fleet import Fleet, config_with_replicas

REPO = Path(__file__).resolve().parents[3]
CONFIG = REPO / "deploy" / "haproxy" / "graspsim-fleet.cfg"


def homes(fleet) -> dict:
    where = {}
    for replica in fleet.replicas:
        with graspsim.connect(replica.address) as direct:
            where.update({s.id: replica.name for s in direct.list_scenes()})
    return where


def demo(server_binary: str, health_probe: str, scenes: int = 30) -> None:
    with tempfile.TemporaryDirectory(prefix="graspsim-fleet-") as work, \
            Fleet(server_binary, str(CONFIG), health_probe, work) as fleet:
        print(f"  3 replicas behind HAProxy at {fleet.address} (gRPC) and {fleet.http_address} (HTTP)")
        with graspsim.connect(fleet.address, fleet=True) as client:
            ids = []
            for i in range(scenes):
                sid = client.create_scene(f"fleet {i}").id
                client.add_object(sid, "cube", builtin="cube_5cm", pose=[0, 0, 0.5, 1, 0, 0, 0])
                ids.append(sid)
            where = homes(fleet)
            print(f"  {scenes} scenes created through the balancer, by replica: {dict(sorted(Counter(where.values()).items()))}")
            victim = fleet.replicas[1]
            victim.kill()
            outcome = Counter()
            for sid in ids:
                try:
                    client.step_simulation(sid, steps=5)
                    outcome["ok"] += 1
                except graspsim.GraspsimError as err:
                    outcome[f"{err.code.name} ({'its' if where[sid] == victim.name else 'other'} scenes)"] += 1
            print(f"  r1 killed (-9): calls on every scene gave {dict(outcome)}")
            victim.start()
            back = sum(1 for sid in ids if where[sid] == victim.name and client.get_scene(sid))
            print(f"  r1 restarted on its data dir: its {back} scenes answer again")
        fleet.add_replica()
        fleet.start_balancer(config_with_replicas(CONFIG.read_text(), 4))
        start = time.perf_counter()
        result = rebalance(fleet.address, [r.address for r in fleet.replicas])
        print(f"  r3 added: {len(result.moved)} of {scenes} scenes changed home and were moved by archive in "
              f"{time.perf_counter() - start:.2f} s ({len(result.failed)} failed); by replica now: "
              f"{dict(sorted(Counter(homes(fleet).values()).items()))}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server-binary", default=str(REPO / "build" / "bin" / "graspsim-server"))
    parser.add_argument("--health-probe", default=str(REPO / "build" / "tools" / "bin" / "grpc-health-probe"))
    args = parser.parse_args(argv)
    demo(args.server_binary, args.health_probe)
    return 0


if __name__ == "__main__":
    sys.exit(main())
