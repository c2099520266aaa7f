"""rpc: the gRPC port under load, beside a bare echo service measured in the same run (issue 11).

ghz (github.com/bojand/ghz, installed from the Go module proxy by tests/bench/run) drives both servers with the
same settings: CONCURRENCY calls in flight over one connection, the load tool on the same 2 cores as the server.
1. graspsim-server, one scene with a table, a cube and the PG70: a warm-up of WARMUP mixed calls, the resident
   memory read, then MIXED_CALLS mixed calls (cheap reads, scene reads, lists, pose writes, single steps);
   "errors" counts every call that did not answer OK (goal 0); "rss_growth_pct" is the resident memory after
   the mix against after the warm-up (goal < 5).
2. The cheap scene call (GetBodyPoses of one body: where is the cube now) and graspsim_echo_server (tests/stress/echo_server.cpp: gRPC's callback
   API answering inline) in turn, SPEED_ROUNDS times SPEED_CALLS calls: "scene_rps" (with its "p99_ms") and
   "echo_rps" are the medians; "scene_vs_echo" is the median over the rounds of each round's scene rate over the
   echo rate measured right before it (goal ≥ 0.8): other load on the 2 cores drifts by ±20 % within a minute,
   and a pair a second apart shares it; each server's CPU µs per call
   ("echo_cpu_us_per_call", "scene_cpu_us_per_call") is the comparison other load on the machine leaves alone.
   The load tool shares the 2 cores, and decoding an answer costs it far more than the server's work (ghz's
   dynamic messages: ~30 µs per echo, ~70 µs per 5-body GetBodyPoses, against ~15-20 µs of server CPU), so the
   all-bodies read is reported beside it ("scene_all_bodies_vs_echo") as what the tool's decoding makes of it.
   ghz runs without call templates (GHZ_FLAGS): rendering one per call would be the tool's own cost again.
3. Calls that end early: watchers that disconnect mid-stream, steps whose deadline expires mid-job, grasp plans
   cancelled mid-run, ENDED_ROUNDS rounds; the server's threads and memory after the last round against after the
   first, which builds what is kept on purpose ("threads_leaked", "rss_growth_pct_ended").
"""
import json
import os
import re
import statistics
import subprocess
import time
from pathlib import Path

import grpc

import graspsim
from graspsim.v1 import grasp_pb2, grasp_pb2_grpc, scene_pb2, scene_pb2_grpc

from _harness import REPO, Server, channel, log

CONCURRENCY = 50
SPEED_ROUNDS = 7
SPEED_CALLS = 40_000
WARMUP = 10_000
# The mix: (method, share of MIXED_CALLS, request). Reads dominate as with viewers and scripts polling a scene.
MIXED_CALLS = 100_000
ENDED_ROUNDS = 4
GHZ = Path(os.environ.get("GHZ", REPO / "build" / "tools" / "bin" / "ghz"))
ECHO_BIN = REPO / "build" / "bin" / "graspsim_echo_server"
PROTO_DIR = REPO / "proto"
# The request is the same for every call: no template to render per call (the tool's CPU, not the server's).
GHZ_FLAGS = ["--disable-template-functions", "--disable-template-data"]
TABLE_TOP, CUBE = 0.75, 0.05


def mix(scene: str):
    pose = {"body_id": "cube", "pose": {"position": {"x": 0.0, "y": 0.0, "z": TABLE_TOP + CUBE / 2},
                                        "orientation": {"w": 1.0}}}
    return [("GetBodyPoses", 0.4, {"scene_id": scene}),
            ("GetScene", 0.2, {"scene_id": scene}),
            ("ListScenes", 0.1, {}),
            ("SetBodyPoses", 0.2, {"scene_id": scene, "poses": [pose]}),
            ("StepSimulation", 0.1, {"scene_id": scene, "steps": 1})]


def ghz(address: str, call: str, data: dict, calls: int, proto: Path, import_path: Path) -> dict:
    """One ghz run; its JSON report."""
    out = subprocess.run([str(GHZ), "--insecure", f"--proto={proto}", f"--import-paths={import_path}",
                          f"--call={call}", f"--data={json.dumps(data)}", f"--concurrency={CONCURRENCY}",
                          f"--total={calls}", "--timeout=20s", "--format=json", *GHZ_FLAGS, address],
                         capture_output=True, text=True, timeout=600)
    if not out.stdout.strip():
        raise RuntimeError(f"ghz {call} gave no report: {out.stderr.strip()[:500]}")
    return json.loads(out.stdout)


def errors_of(report: dict) -> int:
    return sum(n for code, n in (report.get("statusCodeDistribution") or {}).items() if code != "OK")


def p99_ms(report: dict) -> float:
    for entry in report.get("latencyDistribution") or []:
        if entry["percentage"] == 99:
            return round(entry["latency"] / 1e6, 3)  # ns
    return float("nan")


def cpu_seconds(pid: int) -> float:
    fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime + stime


def timed(pid: int, run) -> dict:
    """run()'s ghz report with the server's CPU µs per call: the figure that other load on the machine leaves
    alone (wall-clock rates move by ±20 % with it)."""
    before = cpu_seconds(pid)
    report = run()
    report["cpu_us_per_call"] = 1e6 * (cpu_seconds(pid) - before) / max(1, report["count"])
    return report


def proc_status(pid: int) -> dict:
    fields = dict(line.split(":", 1) for line in open(f"/proc/{pid}/status"))
    return {"rss_kib": int(fields["VmRSS"].split()[0]), "threads": int(fields["Threads"])}


class EchoServer:
    """graspsim_echo_server on a free port, for the life of a with-block."""

    def __enter__(self):
        self.process = subprocess.Popen([str(ECHO_BIN)], stdout=subprocess.PIPE, text=True)
        port = re.match(r"port=(\d+)", self.process.stdout.readline()).group(1)
        self.address = f"127.0.0.1:{port}"
        return self

    def __exit__(self, *exc):
        self.process.kill()
        self.process.wait()


def echo_report(address: str, calls: int) -> dict:
    proto = REPO / "tests" / "stress" / "echo.proto"
    report = ghz(address, "graspsim.bench.Echo/Echo", {"scene_id": "s1"}, calls, proto, proto.parent)
    if errors_of(report):
        raise RuntimeError(f"the echo service failed calls: {report.get('statusCodeDistribution')}")
    return report


def cheap_report(address: str, scene: str, calls: int, body_ids=("cube",)) -> dict:
    method, _, data = mix(scene)[0]
    data = {**data, "body_ids": list(body_ids)}
    return ghz(address, f"graspsim.v1.SceneService/{method}", data, calls, PROTO_DIR / "graspsim" / "v1" / "scene.proto",
               PROTO_DIR)


def build_scene(client) -> str:
    scene = client.create_scene("rpc bench").id
    client.add_object(scene, "table", builtin="table")
    client.add_object(scene, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
    client.add_robot(scene, "pg70", builtin="schunk_pg70", base_pose=[0.3, 0, TABLE_TOP + 0.16, 1, 0, 0, 0])
    return scene


def run_mix(address: str, scene: str, total: int) -> dict:
    """Each method of the mix in turn, its share of `total`; reports by method."""
    scene_proto = PROTO_DIR / "graspsim" / "v1" / "scene.proto"
    return {method: ghz(address, f"graspsim.v1.SceneService/{method}", data, int(total * share), scene_proto,
                        PROTO_DIR)
            for method, share, data in mix(scene)}


def end_calls_early(address: str, scene: str) -> None:
    """Streams the client drops, deadlines that expire mid-job, plans cancelled mid-run."""
    with channel(address) as ch:
        scenes, grasps = scene_pb2_grpc.SceneServiceStub(ch), grasp_pb2_grpc.GraspServiceStub(ch)
        for _ in range(100):  # a viewer that reads one snapshot and goes away
            stream = scenes.WatchScene(scene_pb2.WatchSceneRequest(scene_id=scene))
            next(stream)
            stream.cancel()
        for _ in range(20):  # ten simulated seconds asked with a 50 ms deadline
            try:
                scenes.StepSimulation(scene_pb2.StepSimulationRequest(scene_id=scene, duration=10.0), timeout=0.05)
            except grpc.RpcError as err:
                assert err.code() == grpc.StatusCode.DEADLINE_EXCEEDED, err
        for seed in range(20):  # a grasp plan cancelled after its first progress message
            target = grasp_pb2.GraspTarget(scene_id=scene, body_id="cube")
            stream = grasps.PlanGrasps(grasp_pb2.PlanGraspsRequest(object=target, hand="schunk_pg70", seed=seed + 1,
                                                                    recompute=True))
            next(stream)
            stream.cancel()


def run():
    if not GHZ.exists():
        raise RuntimeError(f"ghz not found at {GHZ}: tests/bench/run rpc installs it")
    with EchoServer() as echo, Server() as server:
        pid = server.process.pid
        with graspsim.connect(server.address) as client:
            scene = build_scene(client)
        run_mix(server.address, scene, WARMUP)
        warm = proc_status(pid)
        reports = run_mix(server.address, scene, MIXED_CALLS)
        mixed = proc_status(pid)
        log("rpc: " + ", ".join(f"{m} {r['rps']:.0f}/s" for m, r in reports.items()))
        # Echo and the cheap scene call alternate, so that the machine's other load hits both alike.
        echo_reports, cheap_reports, all_reports = [], [], []
        for _ in range(SPEED_ROUNDS):
            echo_reports.append(timed(echo.process.pid, lambda: echo_report(echo.address, SPEED_CALLS)))
            cheap_reports.append(timed(pid, lambda: cheap_report(server.address, scene, SPEED_CALLS)))
            all_reports.append(timed(pid, lambda: cheap_report(server.address, scene, SPEED_CALLS, body_ids=())))
        echo_rps = statistics.median(r["rps"] for r in echo_reports)
        cheap = sorted(cheap_reports, key=lambda r: r["rps"])[SPEED_ROUNDS // 2]
        log(f"rpc: echo {[round(r['rps']) for r in echo_reports]}, scene {[round(r['rps']) for r in cheap_reports]}")
        # The first round fills what is built once and kept (the hand models, the object's BVH, pool threads);
        # a leak grows with every round after it.
        rounds = []
        for _ in range(ENDED_ROUNDS):
            end_calls_early(server.address, scene)
            time.sleep(2.0)  # cancelled jobs reach a check point and release what they held
            rounds.append(proc_status(pid))
        first, ended = rounds[0], rounds[-1]
        figures = {
            "echo_rps": round(echo_rps),
            "scene_rps": round(cheap["rps"]),
            "scene_vs_echo": round(statistics.median(s["rps"] / e["rps"] for e, s in zip(echo_reports, cheap_reports)), 3),
            "scene_vs_echo_each": [round(s["rps"] / e["rps"], 3) for e, s in zip(echo_reports, cheap_reports)],
            "p99_ms": p99_ms(cheap),
            "echo_rps_each": [round(r["rps"]) for r in echo_reports],
            "echo_cpu_us_per_call": round(statistics.median(r["cpu_us_per_call"] for r in echo_reports), 1),
            "scene_cpu_us_per_call": round(statistics.median(r["cpu_us_per_call"] for r in cheap_reports), 1),
            "scene_rps_each": [round(r["rps"]) for r in cheap_reports],
            "scene_all_bodies_rps": round(statistics.median(r["rps"] for r in all_reports)),
            "scene_all_bodies_vs_echo": round(statistics.median(r["rps"] for r in all_reports) / echo_rps, 3),
            "scene_all_bodies_cpu_us_per_call": round(statistics.median(r["cpu_us_per_call"] for r in all_reports), 1),
            "errors": sum(errors_of(r) for r in [*reports.values(), *cheap_reports, *all_reports]),
            "mixed_calls": sum(r["count"] for r in reports.values()),
            "rss_growth_pct": round(100 * (mixed["rss_kib"] - warm["rss_kib"]) / warm["rss_kib"], 2),
            "rss_mib_after_warmup": round(warm["rss_kib"] / 1024, 1),
            "rps_by_method": {m: round(r["rps"]) for m, r in reports.items()},
            "p99_ms_by_method": {m: p99_ms(r) for m, r in reports.items()},
            "threads_leaked": ended["threads"] - first["threads"],
            "rss_growth_pct_ended": round(100 * (ended["rss_kib"] - first["rss_kib"]) / first["rss_kib"], 2),
            "rss_mib_by_ended_round": [round(r["rss_kib"] / 1024, 1) for r in rounds],
            "threads_by_ended_round": [r["threads"] for r in rounds],
            "concurrency": CONCURRENCY,
            "loadavg_1min_after": round(os.getloadavg()[0], 2),
        }
        return figures, server.stop()
