"""rpc: the gRPC port under load, beside a bare echo service measured in the same run (issue 11).

ghz (github.com/bojand/ghz, installed from the Go module proxy by tests/bench/run) drives both servers with the
same settings: CONCURRENCY calls in flight over one connection, the load tool on the same 2 cores as the server.
1. graspsim-server, one scene with a table, a cube and the PG70: a warm-up of WARMUP mixed calls, the resident
   memory read, then MIXED_CALLS mixed calls (cheap reads, scene reads, lists, pose writes, single steps), each
   method in turn, so without contention between them (see 3 for that); "errors" counts every call that did not
   answer OK (goal 0); "rss_growth_pct" is the resident memory after the mix against after the warm-up (goal < 5).
2. The cheap scene call (GetBodyPoses of one body: where is the cube now) and graspsim_echo_server
   (tests/stress/echo_server.cpp: gRPC's callback API answering inline) in turn, SPEED_ROUNDS times SPEED_CALLS
   calls: "scene_rps" (with its "p99_ms") and "echo_rps" are the medians; "scene_vs_echo" is the median over the
   rounds of each round's scene rate over the echo rate measured right before it (goal >= 0.8): other load on
   the 2 cores drifts by ±20 % within a minute, and a pair a second apart shares it; each server's CPU µs per
   call ("echo_cpu_us_per_call", "scene_cpu_us_per_call") is the comparison other load on the machine leaves
   alone. The load tool shares the 2 cores, and decoding an answer costs it far more than the server's work
   (ghz's dynamic messages: ~30 µs per echo, ~70 µs per 5-body GetBodyPoses, against ~15-20 µs of server CPU),
   so the all-bodies read is reported beside it ("scene_all_bodies_vs_echo", 5 bodies, over the median echo)
   as what the tool's decoding makes of it. ghz runs without call templates (GHZ_FLAGS): rendering one per call
   would be the tool's own cost again. In the same rounds, GetBodyPoses of every body of a second scene of
   ALL_BODIES bodies (the first scene's five and 15 more cubes): "all_bodies_vs_echo" is the median of each
   round's rate over that round's echo rate (goal >= 0.5), with min, max and each.
3. The interleaved mix (issue 22): the mix's four scene methods (ListScenes reads no scene), with its requests,
   from four ghz processes started together on the one scene (a connection each), each a closed loop of
   workers, CONCURRENCY in all split in the mix's proportions, for INTERLEAVED_S, right after the echo driven by
   the same four processes and workers. Calls/s over all four (the sum of their rates: they overlap but for
   ghz's start-up, < 0.1 s of 4), scene over echo, per repetition: "interleaved_scene_vs_echo" is the median
   over INTERLEAVED_REPS repetitions with min, max and each (reported against 0.8). Workers, not calls, are in
   the mix's proportions: a fixed count per method would leave the slowest running alone at the end, without
   contention; the calls' shares that result are reported ("interleaved_call_share").
4. Calls that end early: watchers that disconnect mid-stream, steps whose deadline expires mid-job, grasp plans
   cancelled mid-run, ENDED_ROUNDS rounds; the server's threads and memory after the last round against after the
   first, which builds what is kept on purpose ("threads_leaked", "rss_growth_pct_ended").
Wall-clock rates move with the machine's other load: "load_avg_1m" (1-min load average at start and end).
"""
import json
import os
import re
import resource
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
# ghz reads the 20-body answer at about a fifth of the one-body rate: fewer calls for about the same time.
ALL_BODIES, ALL_BODIES_CALLS = 20, 10_000
INTERLEAVED_REPS, INTERLEAVED_S = 5, 4  # repetitions (>= 5, issue 22), seconds per run
WARMUP = 10_000
# The mix: (method, share of MIXED_CALLS, request). Reads dominate as with viewers and scripts polling a scene.
MIXED_CALLS = 100_000
ENDED_ROUNDS = 4
GHZ = Path(os.environ.get("GHZ", REPO / "build" / "tools" / "bin" / "ghz"))
ECHO_BIN = REPO / "build" / "bin" / "graspsim_echo_server"
PROTO_DIR = REPO / "proto"
SCENE_PROTO, ECHO_PROTO = PROTO_DIR / "graspsim" / "v1" / "scene.proto", REPO / "tests" / "stress" / "echo.proto"
ECHO_CALL, ECHO_DATA = "graspsim.bench.Echo/Echo", {"scene_id": "s1"}
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


def ghz_command(address: str, call: str, data: dict, proto: Path, import_path: Path, *load: str) -> list:
    return [str(GHZ), "--insecure", f"--proto={proto}", f"--import-paths={import_path}", f"--call={call}",
            f"--data={json.dumps(data)}", "--timeout=20s", "--format=json", *GHZ_FLAGS, *load, address]


def ghz_report(call: str, stdout: str, stderr: str) -> dict:
    if not stdout.strip():
        raise RuntimeError(f"ghz {call} gave no report: {stderr.strip()[:500]}")
    return json.loads(stdout)


def ghz(address: str, call: str, data: dict, calls: int, proto: Path, import_path: Path) -> dict:
    """One ghz run; its JSON report."""
    out = subprocess.run(ghz_command(address, call, data, proto, import_path, f"--concurrency={CONCURRENCY}",
                                     f"--total={calls}"), capture_output=True, text=True, timeout=600)
    return ghz_report(call, out.stdout, out.stderr)


def ghz_together(runs: list, seconds: float) -> list:
    """ghz runs (address, call, data, proto, import_path, workers) started together, each for `seconds`; their
    reports. Calls still in flight at the end are left out of the counts ("ignore"), not counted as errors."""
    procs = [(run[1], subprocess.Popen(ghz_command(*run[:5], f"--concurrency={run[5]}", f"--duration={seconds}s",
                                                   "--duration-stop=ignore"),
                                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)) for run in runs]
    return [ghz_report(call, *proc.communicate(timeout=seconds + 120)) for call, proc in procs]


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


def ghz_cpu_seconds() -> float:
    """CPU time of the ghz processes run and waited for so far: what the load tool took of the shared cores."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(pid: int, run) -> dict:
    """run()'s ghz report with the server's CPU µs per call: the figure that other load on the machine leaves
    alone (wall-clock rates move by ±20 % with it); and ghz's own."""
    before, ghz_before = cpu_seconds(pid), ghz_cpu_seconds()
    report = run()
    report["cpu_us_per_call"] = 1e6 * (cpu_seconds(pid) - before) / max(1, report["count"])
    report["ghz_cpu_us_per_call"] = 1e6 * (ghz_cpu_seconds() - ghz_before) / max(1, report["count"])
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
    report = ghz(address, ECHO_CALL, ECHO_DATA, calls, ECHO_PROTO, ECHO_PROTO.parent)
    if errors_of(report):
        raise RuntimeError(f"the echo service failed calls: {report.get('statusCodeDistribution')}")
    return report


def cheap_report(address: str, scene: str, calls: int, body_ids=("cube",)) -> dict:
    method, _, data = mix(scene)[0]
    data = {**data, "body_ids": list(body_ids)}
    return ghz(address, f"graspsim.v1.SceneService/{method}", data, calls, SCENE_PROTO, PROTO_DIR)


def build_scene(client, more_cubes: int = 0) -> str:
    """The table, the cube and the PG70 (5 bodies), and more_cubes cubes in rows of 5 on the table's left half."""
    scene = client.create_scene(f"rpc bench {5 + more_cubes} bodies" if more_cubes else "rpc bench").id
    client.add_object(scene, "table", builtin="table")
    client.add_object(scene, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
    client.add_robot(scene, "pg70", builtin="schunk_pg70", base_pose=[0.3, 0, TABLE_TOP + 0.16, 1, 0, 0, 0])
    for i in range(more_cubes):
        client.add_object(scene, f"cube{i + 2}", builtin="cube_5cm",
                          pose=[-0.1 - 0.1 * (i // 5), -0.2 + 0.1 * (i % 5), TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
    return scene


def run_mix(address: str, scene: str, total: int) -> dict:
    """Each method of the mix in turn, its share of `total`; reports by method."""
    return {method: ghz(address, f"graspsim.v1.SceneService/{method}", data, int(total * share), SCENE_PROTO,
                        PROTO_DIR)
            for method, share, data in mix(scene)}


def interleaved_workers(scene: str) -> list:
    """(method, workers, request) of the mix's scene methods, CONCURRENCY workers in the mix's proportions."""
    methods = [m for m in mix(scene) if m[0] != "ListScenes"]
    total = sum(share for _, share, _ in methods)
    spec = [(method, round(CONCURRENCY * share / total), data) for method, share, data in methods]
    assert sum(n for _, n, _ in spec) == CONCURRENCY, spec
    return spec


def run_interleaved(pid: int, runs: list) -> dict:
    """ghz_together(runs): calls/s over all runs (their rates add up: they run at the same time), the server's
    CPU µs per call, each run's report by method."""
    before, ghz_before = cpu_seconds(pid), ghz_cpu_seconds()
    reports = ghz_together(runs, INTERLEAVED_S)
    count = sum(r["count"] for r in reports)
    return {"rps": sum(r["rps"] for r in reports), "count": count,
            "cpu_us_per_call": 1e6 * (cpu_seconds(pid) - before) / max(1, count),
            "ghz_cpu_us_per_call": 1e6 * (ghz_cpu_seconds() - ghz_before) / max(1, count),
            "by_method": {run[1].rsplit("/", 1)[1]: r for run, r in zip(runs, reports)}}


def paired_ratios(scene_reports: list, echo_reports: list) -> list:
    """Each repetition's scene rate over the echo rate measured right before it: the pair shares the drift."""
    return [s["rps"] / e["rps"] for e, s in zip(echo_reports, scene_reports)]


def spread(key: str, ratios: list) -> dict:
    """A ratio's median over the repetitions, with min, max and each."""
    return {key: round(statistics.median(ratios), 3), f"{key}_min": round(min(ratios), 3),
            f"{key}_max": round(max(ratios), 3), f"{key}_each": [round(r, 3) for r in ratios]}


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
    load_start = round(os.getloadavg()[0], 2)
    with EchoServer() as echo, Server() as server:
        pid = server.process.pid
        with graspsim.connect(server.address) as client:
            scene = build_scene(client)
        run_mix(server.address, scene, WARMUP)
        warm = proc_status(pid)
        reports = run_mix(server.address, scene, MIXED_CALLS)
        mixed = proc_status(pid)
        log("rpc: " + ", ".join(f"{m} {r['rps']:.0f}/s" for m, r in reports.items()))
        # Made after the mix, whose ListScenes would otherwise list it too.
        with graspsim.connect(server.address) as client:
            scene20 = build_scene(client, more_cubes=ALL_BODIES - 5)
        # Echo and the scene calls alternate, so that the machine's other load hits both alike.
        echo_reports, cheap_reports, all_reports, all20_reports = [], [], [], []
        for _ in range(SPEED_ROUNDS):
            echo_reports.append(timed(echo.process.pid, lambda: echo_report(echo.address, SPEED_CALLS)))
            cheap_reports.append(timed(pid, lambda: cheap_report(server.address, scene, SPEED_CALLS)))
            all_reports.append(timed(pid, lambda: cheap_report(server.address, scene, SPEED_CALLS, body_ids=())))
            all20_reports.append(timed(pid, lambda: cheap_report(server.address, scene20, ALL_BODIES_CALLS,
                                                                 body_ids=())))
        echo_rps = statistics.median(r["rps"] for r in echo_reports)
        cheap = sorted(cheap_reports, key=lambda r: r["rps"])[SPEED_ROUNDS // 2]
        log(f"rpc: echo {[round(r['rps']) for r in echo_reports]}, scene {[round(r['rps']) for r in cheap_reports]}, "
            f"{ALL_BODIES} bodies {[round(r['rps']) for r in all20_reports]}")
        # The interleaved mix and its echo: the same ghz processes and workers, alternating.
        workers = interleaved_workers(scene)
        echo_runs = [(echo.address, ECHO_CALL, ECHO_DATA, ECHO_PROTO, ECHO_PROTO.parent, n) for _, n, _ in workers]
        scene_runs = [(server.address, f"graspsim.v1.SceneService/{method}", data, SCENE_PROTO, PROTO_DIR, n)
                      for method, n, data in workers]
        echo_mixes, scene_mixes = [], []
        for _ in range(INTERLEAVED_REPS):
            echo_mixes.append(run_interleaved(echo.process.pid, echo_runs))
            scene_mixes.append(run_interleaved(pid, scene_runs))
        log(f"rpc: interleaved echo {[round(r['rps']) for r in echo_mixes]}, "
            f"scene {[round(r['rps']) for r in scene_mixes]}")
        interleaved_calls = {m: sum(r["by_method"][m]["count"] for r in scene_mixes) for m, _, _ in workers}
        # The first round fills what is built once and kept (the hand models, the object's BVH, pool threads);
        # a leak grows with every round after it.
        rounds = []
        for _ in range(ENDED_ROUNDS):
            end_calls_early(server.address, scene)
            time.sleep(2.0)  # cancelled jobs reach a check point and release what they held
            rounds.append(proc_status(pid))
        first, ended = rounds[0], rounds[-1]
        cheap_ratios = paired_ratios(cheap_reports, echo_reports)
        all20_ratios = paired_ratios(all20_reports, echo_reports)
        interleaved_ratios = paired_ratios(scene_mixes, echo_mixes)
        figures = {
            "echo_rps": round(echo_rps),
            "scene_rps": round(cheap["rps"]),
            "scene_vs_echo": round(statistics.median(cheap_ratios), 3),
            "scene_vs_echo_each": [round(r, 3) for r in cheap_ratios],
            "scene_vs_echo_min": round(min(cheap_ratios), 3), "scene_vs_echo_max": round(max(cheap_ratios), 3),
            "p99_ms": p99_ms(cheap),
            "echo_rps_each": [round(r["rps"]) for r in echo_reports],
            "echo_cpu_us_per_call": round(statistics.median(r["cpu_us_per_call"] for r in echo_reports), 1),
            "scene_cpu_us_per_call": round(statistics.median(r["cpu_us_per_call"] for r in cheap_reports), 1),
            "scene_rps_each": [round(r["rps"]) for r in cheap_reports],
            "scene_all_bodies_rps": round(statistics.median(r["rps"] for r in all_reports)),
            "scene_all_bodies_vs_echo": round(statistics.median(r["rps"] for r in all_reports) / echo_rps, 3),
            "scene_all_bodies_cpu_us_per_call": round(statistics.median(r["cpu_us_per_call"] for r in all_reports), 1),
            **spread("all_bodies_vs_echo", all20_ratios),
            "all_bodies_count": ALL_BODIES,
            "all_bodies_rps": round(statistics.median(r["rps"] for r in all20_reports)),
            "all_bodies_cpu_us_per_call": round(statistics.median(r["cpu_us_per_call"] for r in all20_reports), 1),
            "all_bodies_errors": sum(errors_of(r) for r in all20_reports),
            **spread("interleaved_scene_vs_echo", interleaved_ratios),
            "interleaved_rps": round(statistics.median(r["rps"] for r in scene_mixes)),
            "interleaved_echo_rps": round(statistics.median(r["rps"] for r in echo_mixes)),
            "interleaved_workers": {m: n for m, n, _ in workers},
            "interleaved_call_share": {m: round(n / sum(interleaved_calls.values()), 3)
                                       for m, n in interleaved_calls.items()},
            "interleaved_rps_by_method": {m: round(statistics.median(r["by_method"][m]["rps"] for r in scene_mixes))
                                          for m in interleaved_calls},
            "interleaved_p99_ms_by_method": {m: statistics.median(p99_ms(r["by_method"][m]) for r in scene_mixes)
                                             for m in interleaved_calls},
            "interleaved_cpu_us_per_call": round(statistics.median(r["cpu_us_per_call"] for r in scene_mixes), 1),
            "interleaved_echo_cpu_us_per_call": round(statistics.median(r["cpu_us_per_call"] for r in echo_mixes), 1),
            # What the load tool took per call, beside the server's: on shared cores it is taken from the server.
            "ghz_cpu_us_per_call": {name: round(statistics.median(r["ghz_cpu_us_per_call"] for r in runs), 1)
                                    for name, runs in [("echo", echo_reports), ("scene", cheap_reports),
                                                       ("scene_all_bodies", all_reports), ("all_bodies", all20_reports),
                                                       ("interleaved_echo", echo_mixes), ("interleaved", scene_mixes)]},
            "interleaved_errors": sum(errors_of(r) for mix_ in [*echo_mixes, *scene_mixes]
                                      for r in mix_["by_method"].values()),
            "goal_scene_vs_echo_0_8_met": statistics.median(cheap_ratios) >= 0.8,
            "goal_all_bodies_0_5_met": statistics.median(all20_ratios) >= 0.5,
            "goal_interleaved_0_8_met": statistics.median(interleaved_ratios) >= 0.8,
            "repetitions": {"speed": SPEED_ROUNDS, "interleaved": INTERLEAVED_REPS},
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
            "load_avg_1m": [load_start, round(os.getloadavg()[0], 2)],
        }
        return figures, server.stop()
