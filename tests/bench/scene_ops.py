"""scene_ops: latency of unary calls on one small scene (PG70, table, cube), and calls per second with 1 and 4
client threads — on 4 different scenes, and for contrast on one shared scene.

Calls go through the raw generated stub with requests built beforehand, so the figures are the server plus
grpc-python's per-call cost, not the convenience client's message building. grpc.health.v1 Check on the same
server is measured the same way: it is the floor of that path (no scene code at all).
"""
import threading
import time

import graspsim
from graspsim.v1 import scene_pb2, scene_pb2_grpc
from grpc_health.v1 import health_pb2, health_pb2_grpc

from _harness import Server, channel, log, ms_stats

WARMUP = 200
CALLS = 5000           # per operation, for the latency percentiles
THROUGHPUT_S = 3.0     # per throughput configuration


def build_scene(client) -> str:
    scene_id = client.create_scene("bench").id
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70", base_pose=[0, 0, 1.0, 0, 1, 0, 0])
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, 0.8, 1, 0, 0, 0])
    return scene_id


def set_pose_requests(scene_id: str):
    """Two SetBodyPoses requests (one body), used alternately so that every call really changes the scene."""
    requests = []
    for x in (0.0, 0.001):
        request = scene_pb2.SetBodyPosesRequest(scene_id=scene_id)
        request.poses.add(body_id="cube", pose=graspsim.as_pose([x, 0, 0.8, 1, 0, 0, 0]).to_proto())
        requests.append(request)
    return requests


def operations(ch, scene_id: str) -> dict:
    """name -> (stub method, two requests used alternately)."""
    stub, health = scene_pb2_grpc.SceneServiceStub(ch), health_pb2_grpc.HealthStub(ch)
    fingers = []
    for q in (0.01, 0.02):
        request = scene_pb2.SetJointPositionsRequest(scene_id=scene_id)
        request.positions.add(joint_id="pg70/finger_left_joint", position=q)
        fingers.append(request)
    get = scene_pb2.GetSceneRequest(scene_id=scene_id, include_geometry=False)
    check = health_pb2.HealthCheckRequest(service="")
    return {"set_body_poses": (stub.SetBodyPoses, set_pose_requests(scene_id)),
            "set_joint_positions": (stub.SetJointPositions, fingers),
            "get_scene": (stub.GetScene, [get, get]),
            "health_check": (health.Check, [check, check])}


def latencies(call, requests, calls: int):
    """Durations (s) of calls back to back, after a warm-up."""
    for i in range(WARMUP):
        call(requests[i % 2], timeout=10)
    out = []
    for i in range(calls):
        t0 = time.perf_counter()
        call(requests[i % 2], timeout=10)
        out.append(time.perf_counter() - t0)
    return out


def throughput(address: str, scene_ids, duration_s: float):
    """Threads (one per scene id, each with its own connection) call SetBodyPoses back to back for duration_s;
    returns (calls per second in total, calls of each thread)."""
    stubs = [scene_pb2_grpc.SceneServiceStub(channel(address)) for _ in scene_ids]
    counts = [0] * len(scene_ids)
    barrier = threading.Barrier(len(scene_ids) + 1)
    stop_at = [0.0]

    def worker(index: int, scene_id: str):
        requests = set_pose_requests(scene_id)
        barrier.wait()
        n = 0
        while time.perf_counter() < stop_at[0]:
            stubs[index].SetBodyPoses(requests[n % 2], timeout=10)
            n += 1
        counts[index] = n

    threads = [threading.Thread(target=worker, args=(i, s)) for i, s in enumerate(scene_ids)]
    for t in threads:
        t.start()
    start = time.perf_counter()
    stop_at[0] = start + duration_s
    barrier.wait()
    for t in threads:
        t.join()
    elapsed = time.perf_counter() - start
    return round(sum(counts) / elapsed), counts


def run():
    with Server() as server, graspsim.connect(server.address) as client:
        scene_ids = [build_scene(client) for _ in range(4)]
        figures = {"calls_per_op": CALLS, "client": "python-threads, raw stub"}
        for name, (call, requests) in operations(channel(server.address), scene_ids[0]).items():
            log(f"{name}: {CALLS} calls")
            figures.update(ms_stats(name, latencies(call, requests, CALLS)))
        for label, ids in [("1_thread", scene_ids[:1]), ("4_threads_4_scenes", scene_ids),
                           ("4_threads_1_scene", scene_ids[:1] * 4)]:
            log(f"throughput {label}: {THROUGHPUT_S:g} s")
            per_s, counts = throughput(server.address, ids, THROUGHPUT_S)
            figures[f"set_body_poses_per_s_{label}"] = per_s
            if len(counts) > 1:
                figures[f"thread_calls_min_max_{label}"] = [min(counts), max(counts)]
    return figures, server.exit_code
