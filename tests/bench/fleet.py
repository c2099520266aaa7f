"""fleet: a fleet of graspsim-server replicas behind HAProxy on this machine (issue 23, docs/scaling.md):
routing by scene, a replica killed under load, its recovery, the balancer's cost, and what one replica holds.

Workload: REPLICAS servers (each --compute-threads=1, its own data dir) behind HAProxy 2.6 with
deploy/haproxy/graspsim-fleet.cfg as shipped (graspsim.testing.fleet). SCENES scenes are created through the
balancer by a fleet client (connect(fleet=True): client-chosen ids), each with the built-in table and a 5 cm cube.

- misrouted_calls: scene calls through the balancer (StepSimulation, GetBodyPoses, GetScene of every scene)
  that did not reach the scene's home, seen as NOT_FOUND (a scene exists on one replica only: asked of each
  replica directly, scenes_on_two_replicas must be 0); replica_scene_counts: the spread.
- The kill: two client threads loop over all scenes with GetBodyPoses through the balancer; after KILL_AFTER_S
  one replica is killed with SIGKILL, the load goes on for KILL_FOR_S. errors_other_replicas_during_kill: failed
  calls for scenes of the live replicas (goal 0); killed_replica_error_codes: the status codes of calls for the
  killed replica's scenes (goal UNAVAILABLE only). The replica is then restarted on the same ports and data dir:
  recovered_scenes_fraction = its scenes whose cube answers again through the balancer / its scenes (goal 1.0).
- Balancer cost: ghz (concurrency CONCURRENCY, OVERHEAD_CALLS per run) calls GetBodyPoses of one body of one
  scene directly at its home replica and through HAProxy (with the graspsim-scene-id header), REPS runs each,
  interleaved; balancer_overhead_pct = (1 - balanced calls/s / direct calls/s) * 100 of the medians, with the
  latency medians and [min, max] spreads. direct_calls_per_s is also one replica's capacity for this cheap call.
- balancer_cpu_us_per_call: HAProxy's own CPU time (user + system) per balanced call: the cost that stays when
  the balancer has cores of its own (on these 2 cores it is taken from the server and ghz, hence the
  throughput overhead).
- moved_fraction_on_adding_a_replica: the scenes whose home changes when a (REPLICAS+1)th replica joins the ring
  (after the balancer's reload their calls answer NOT_FOUND until moved); rebalance_moved, rebalance_failed,
  rebalance_s: graspsim.fleet.rebalance moving them by archive (ExportScene → ImportScene → DeleteScene);
  unreachable_after_rebalance: scenes whose cube does not answer through the balancer afterwards (goal 0).
- replica_idle_rss_mib: a replica's RSS before it holds a scene (median of the replicas);
  memory_kib_per_scene: the RSS growth of one replica over the scenes it holds / their count (table + cube each);
  memory_kib_per_gripper_scene: the same for 20 scenes of the work cycle's kind (PG70 on its z axis, table, cube,
  10 steps simulated).
Environment: GRASPSIM_FLEET_SCENES (300), GRASPSIM_FLEET_REPS (5).
"""
import json
import os
import statistics
import subprocess
import tempfile
import threading
import time
from collections import Counter

import graspsim
from graspsim.fleet import rebalance
from graspsim.testing.fleet import Fleet, config_with_replicas

from _harness import REPO, SERVER_BIN, log
from rpc import GHZ, GHZ_FLAGS, PROTO_DIR, cpu_seconds, proc_status

REPLICAS = 3
SCENES = int(os.environ.get("GRASPSIM_FLEET_SCENES", "300"))
REPS = int(os.environ.get("GRASPSIM_FLEET_REPS", "5"))
CONCURRENCY = 8
OVERHEAD_CALLS = 5000
KILL_AFTER_S, KILL_FOR_S = 1.0, 3.0
CONFIG = REPO / "deploy" / "haproxy" / "graspsim-fleet.cfg"
PROBE = REPO / "build" / "tools" / "bin" / "grpc-health-probe"


def homes(fleet) -> dict:
    where, twice = {}, 0
    for replica in fleet.replicas:
        with graspsim.connect(replica.address) as direct:
            for summary in direct.list_scenes():
                twice += summary.id in where
                where[summary.id] = replica.name
    return where, twice


def make_scenes(fleet) -> list:
    with graspsim.connect(fleet.address, fleet=True) as client:
        ids = []
        for i in range(SCENES):
            sid = client.create_scene(f"fleet bench {i}").id
            client.add_object(sid, "table", builtin="table")
            client.add_object(sid, "cube", builtin="cube_5cm", pose=[0, 0, 0.775, 1, 0, 0, 0])
            ids.append(sid)
    return ids


def misrouted(fleet, scenes) -> int:
    count = 0
    with graspsim.connect(fleet.address, fleet=True) as client:
        for sid in scenes:
            for call in (lambda: client.step_simulation(sid, steps=1), lambda: client.get_body_poses(sid, ["cube"]),
                         lambda: client.get_scene(sid)):
                try:
                    call()
                except graspsim.NotFound:
                    count += 1
    return count


def kill_under_load(fleet, scenes, where) -> dict:
    victim = fleet.replicas[1]
    calls, errors, stop = Counter(), Counter(), threading.Event()

    def load(ids):
        with graspsim.connect(fleet.address, fleet=True, call_timeout=10) as client:
            while not stop.is_set():
                for sid in ids:
                    mine = where[sid] == victim.name
                    calls[mine] += 1
                    try:
                        client.get_body_poses(sid, ["cube"])
                    except graspsim.GraspsimError as err:
                        errors[mine, err.code.name] += 1

    threads = [threading.Thread(target=load, args=(scenes[k::2],)) for k in range(2)]
    for t in threads:
        t.start()
    time.sleep(KILL_AFTER_S)
    victim.kill()
    time.sleep(KILL_FOR_S)
    stop.set()
    for t in threads:
        t.join()
    victim.start()
    its = [s for s in scenes if where[s] == victim.name]
    back = 0
    with graspsim.connect(fleet.address, fleet=True) as client:
        for sid in its:
            try:
                back += "cube" in client.get_body_poses(sid, ["cube"])
            except graspsim.GraspsimError:
                pass
    return {"calls_during_kill": sum(calls.values()),
            "errors_other_replicas_during_kill": sum(n for (mine, _), n in errors.items() if not mine),
            "killed_replica_error_codes": {code: n for (mine, code), n in errors.items() if mine},
            "recovered_scenes_fraction": round(back / max(1, len(its)), 4), "killed_replica_scenes": len(its)}


def ghz_run(address: str, scene: str) -> dict:
    data = {"scene_id": scene, "body_ids": ["cube"]}
    out = subprocess.run([str(GHZ), "--insecure", f"--proto={PROTO_DIR / 'graspsim' / 'v1' / 'scene.proto'}",
                          f"--import-paths={PROTO_DIR}", "--call=graspsim.v1.SceneService/GetBodyPoses",
                          f"--data={json.dumps(data)}", f"--metadata={json.dumps({'graspsim-scene-id': scene})}",
                          f"--concurrency={CONCURRENCY}", f"--total={OVERHEAD_CALLS}", "--timeout=20s",
                          "--format=json", *GHZ_FLAGS, address], capture_output=True, text=True, timeout=600)
    report = json.loads(out.stdout)
    bad = sum(n for code, n in (report.get("statusCodeDistribution") or {}).items() if code != "OK")
    if bad:
        raise RuntimeError(f"ghz at {address}: {report.get('statusCodeDistribution')}")
    p50 = next(e["latency"] for e in report["latencyDistribution"] if e["percentage"] == 50) / 1e3
    return {"calls_per_s": report["rps"], "p50_us": p50}


def overhead(fleet, scene, home) -> dict:
    direct, balanced = [], []
    ghz_run(home.address, scene)  # warm-up of both paths
    ghz_run(fleet.address, scene)
    for rep in range(REPS):
        order = [(direct, home.address), (balanced, fleet.address)]
        for sink, address in (order if rep % 2 == 0 else order[::-1]):
            before = cpu_seconds(fleet.balancer.pid)
            sink.append(ghz_run(address, scene))
            sink[-1]["balancer_cpu_us_per_call"] = 1e6 * (cpu_seconds(fleet.balancer.pid) - before) / OVERHEAD_CALLS
    med = lambda runs, key: statistics.median(r[key] for r in runs)
    span = lambda runs, key: [round(min(r[key] for r in runs), 1), round(max(r[key] for r in runs), 1)]
    return {"direct_calls_per_s": round(med(direct, "calls_per_s"), 1), "direct_calls_per_s_spread": span(direct, "calls_per_s"),
            "balanced_calls_per_s": round(med(balanced, "calls_per_s"), 1),
            "balanced_calls_per_s_spread": span(balanced, "calls_per_s"),
            "direct_p50_us": round(med(direct, "p50_us"), 1), "balanced_p50_us": round(med(balanced, "p50_us"), 1),
            "balancer_overhead_pct": round(100 * (1 - med(balanced, "calls_per_s") / med(direct, "calls_per_s")), 2),
            "balancer_cpu_us_per_call": round(med(balanced, "balancer_cpu_us_per_call"), 1),
            "balancer_cpu_us_per_call_spread": span(balanced, "balancer_cpu_us_per_call")}


def grow(fleet, scenes) -> dict:
    """A replica added, the balancer reloaded, the moved scenes moved by graspsim.fleet.rebalance."""
    fleet.add_replica()
    fleet.start_balancer(config_with_replicas(CONFIG.read_text(), REPLICAS + 1))
    addresses = [r.address for r in fleet.replicas]
    planned = rebalance(fleet.address, addresses, dry_run=True)
    start = time.perf_counter()
    done = rebalance(fleet.address, addresses)
    seconds = time.perf_counter() - start
    unreachable = 0
    with graspsim.connect(fleet.address, fleet=True) as client:
        for sid in scenes:
            try:
                client.get_body_poses(sid, ["cube"])
            except graspsim.GraspsimError:
                unreachable += 1
    return {"moved_fraction_on_adding_a_replica": round(len(planned.moved) / len(scenes), 4),
            "rebalance_moved": len(done.moved), "rebalance_failed": len(done.failed),
            "rebalance_s": round(seconds, 2), "unreachable_after_rebalance": unreachable}


def gripper_scene_memory(fleet, count: int = 20) -> float:
    """RSS growth per scene of the work cycle's kind (the PG70 on its z axis, the table, the cube), one replica."""
    replica = fleet.replicas[0]
    with graspsim.connect(replica.address) as client:
        rss = proc_status(replica.process.pid)["rss_kib"]
        made = []
        for i in range(count):
            sid = client.create_scene(f"gripper {i}").id
            client.add_robot(sid, "gripper", builtin="schunk_pg70_on_z_axis", base_pose=[0, 0, 1.05, 1, 0, 0, 0])
            client.add_object(sid, "table", builtin="table")
            client.add_object(sid, "cube", builtin="cube_5cm", pose=[0, 0, 0.775, 1, 0, 0, 0])
            client.step_simulation(sid, steps=10)
            made.append(sid)
        per_scene = (proc_status(replica.process.pid)["rss_kib"] - rss) / count
        for sid in made:
            client.delete_scene(sid)
    return round(per_scene, 1)


def run():
    if not GHZ.is_file() or not PROBE.is_file():
        raise RuntimeError(f"{GHZ} or {PROBE} missing: tests/bench/run fleet installs them")
    load_start = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="graspsim-fleet-bench-") as work, \
            Fleet(str(SERVER_BIN), str(CONFIG), str(PROBE), work, REPLICAS, ["--compute-threads=1"]) as fleet:
        rss_before = {r.name: proc_status(r.process.pid)["rss_kib"] for r in fleet.replicas}
        log(f"fleet: {SCENES} scenes through the balancer")
        scenes = make_scenes(fleet)
        where, twice = homes(fleet)
        counts = Counter(where.values())
        per_scene = [(proc_status(r.process.pid)["rss_kib"] - rss_before[r.name]) / counts[r.name]
                     for r in fleet.replicas if counts[r.name]]
        figures = {"replicas": REPLICAS, "scenes": SCENES, "scenes_on_two_replicas": twice,
                   "replica_scene_counts": dict(sorted(counts.items())),
                   "misrouted_calls": misrouted(fleet, scenes),
                   "memory_kib_per_scene": round(statistics.median(per_scene), 1),
                   "replica_idle_rss_mib": round(statistics.median(rss_before.values()) / 1024, 1)}
        log("fleet: balancer overhead (ghz)")
        figures.update(overhead(fleet, scenes[0], next(r for r in fleet.replicas if r.name == where[scenes[0]])))
        log("fleet: a replica killed under load")
        figures.update(kill_under_load(fleet, scenes, where))
        figures["memory_kib_per_gripper_scene"] = gripper_scene_memory(fleet)
        log("fleet: a fourth replica, rebalanced")
        figures.update(grow(fleet, scenes))
    figures.update({"repetitions": REPS, "concurrency": CONCURRENCY, "load_avg_start": round(load_start, 2),
                    "load_avg_end": round(os.getloadavg()[0], 2)})
    return figures, 0
