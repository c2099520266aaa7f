"""watch: WatchScene fan-out. 20 watchers read, 1 watcher never reads; a writer changes the cube's pose 500 times
at ~200 Hz (server --watch-max-rate-hz=1000, streams ask for 1000 Hz).

Delivery latency of change r at a watcher = arrival of its first snapshot with revision >= r minus the time the
writer got SetBodyPoses' answer (revision r). It can be negative: the server starts the snapshot writes before
it answers the writer, and the writer may be scheduled after the watchers. delivery_from_send counts from the
moment the writer sent the call instead (request + commit + fan-out + snapshot transfer). Snapshots may be
skipped by design (the newest wins), so each watcher's share of the changes is reported, not asserted.

Each reading watcher is a process of its own on its own connection, as viewers are, so that the GIL plays no
part (a version with 20 threads in one process gave similar figures on 2 cores). time.perf_counter is
CLOCK_MONOTONIC, one clock for all processes. The never-reader stays in this process: it never runs.
"""
import bisect
import multiprocessing
import statistics
import threading
import time

import graspsim
import grpc
import numpy as np
from graspsim.v1 import scene_pb2, scene_pb2_grpc

from _harness import Server, channel, log, ms_stats, sleep_until
from scene_ops import build_scene, set_pose_requests

WATCHERS = 20
CHANGES = 500
PERIOD_S = 1 / 200
RATE_HZ = 1000.0
DRAIN_S = 1.0  # after the last change, time given to the watchers to receive it before they are stopped
# The never-reader's connection: a small stream window and no BDP probing, so that its flow-control window fills
# after a few snapshots and the server must hold (and skip) further ones for it rather than buffer them.
STALLED_OPTIONS = [("grpc.http2.bdp_probe", 0), ("grpc.http2.lookahead_bytes", 16384)]


def write(stub, scene_id: str):
    """CHANGES SetBodyPoses at PERIOD_S on an absolute schedule; returns [(revision, send time, ack time)]."""
    requests = set_pose_requests(scene_id)
    out = []
    next_at = time.perf_counter()
    for i in range(CHANGES):
        next_at += PERIOD_S
        sleep_until(next_at)
        t0 = time.perf_counter()
        revision = stub.SetBodyPoses(requests[i % 2], timeout=10).revision
        t1 = time.perf_counter()
        out.append((revision, t0, t1))
    return out


def watcher_process(address: str, scene_id: str, stop, results) -> None:
    """One reading watcher (a spawned process): records (revision, arrival time) per snapshot until stop is set,
    then puts ("done", revisions, arrivals, error) on results; ("ready",) after the first snapshot."""
    ch = channel(address)
    call = scene_pb2_grpc.SceneServiceStub(ch).WatchScene(
        scene_pb2.WatchSceneRequest(scene_id=scene_id, max_rate_hz=RATE_HZ))
    threading.Thread(target=lambda: (stop.wait(), call.cancel()), daemon=True).start()
    revisions, arrivals, error = [], [], None
    try:
        for snap in call:
            arrivals.append(time.perf_counter())  # first, before anything else is done with the message
            revisions.append(snap.revision)
            if len(revisions) == 1:
                results.put(("ready",))
    except grpc.RpcError as err:
        if err.code() != grpc.StatusCode.CANCELLED:
            error = f"{err.code().name}: {err.details()}"
            results.put(("ready",))
    results.put(("done", revisions, arrivals, error))
    ch.close()


def delivery(revisions, arrivals, changes):
    """Arrival time of each change at one watcher (None: never delivered), and the share of revisions it saw."""
    arrived, seen = [], set(revisions)
    for revision, _, _ in changes:
        i = bisect.bisect_left(revisions, revision)  # revisions arrive in increasing order
        arrived.append(arrivals[i] if i < len(revisions) else None)
    return arrived, sum(r in seen for r, _, _ in changes) / len(changes)


def run():
    spawn = multiprocessing.get_context("spawn")  # fork is unsafe once gRPC has started its threads
    # Debug level: one log line per request with its handler time, to tell server time from client time.
    with Server(f"--watch-max-rate-hz={RATE_HZ:g}", "--log-level=debug") as server, \
            graspsim.connect(server.address) as client:
        scene_id = build_scene(client)
        stub = scene_pb2_grpc.SceneServiceStub(channel(server.address))
        log(f"writer alone: {CHANGES} changes at {1 / PERIOD_S:g} Hz")
        alone = write(stub, scene_id)

        stalled_channel = channel(server.address, *STALLED_OPTIONS)
        stalled = scene_pb2_grpc.SceneServiceStub(stalled_channel).WatchScene(
            scene_pb2.WatchSceneRequest(scene_id=scene_id, max_rate_hz=RATE_HZ))
        stalled.initial_metadata()  # the server has accepted the stream; it is not read until the end
        log(f"starting {WATCHERS} watcher processes")
        stop, results = spawn.Event(), spawn.Queue()
        processes = [spawn.Process(target=watcher_process, args=(server.address, scene_id, stop, results),
                                   daemon=True) for _ in range(WATCHERS)]
        for p in processes:
            p.start()
        for _ in processes:
            results.get(timeout=60)
        log(f"writer with {WATCHERS} + 1 watchers: {CHANGES} changes")
        started = time.perf_counter()
        watched = write(stub, scene_id)
        writer_hz = CHANGES / (time.perf_counter() - started)
        final = watched[-1][0]
        time.sleep(DRAIN_S)
        stalled_active = stalled.is_active()
        stop.set()
        reports = [results.get(timeout=30) for _ in processes]
        for p in processes:
            p.join(10)
        # The never-reader now reads: it should get a few held snapshots and then the newest, not a queue of 500.
        drained = []
        for snap in stalled:
            drained.append(snap.revision)
            if snap.revision >= final:
                break
        stalled.cancel()
        stalled_channel.close()
        handler = server.handler_seconds("SetBodyPoses")  # the writer's calls only: alone, then watched

    errors = [error for _, _, _, error in reports if error]
    if errors:
        raise RuntimeError(f"{len(errors)} watchers failed: {errors[0]}")
    from_ack, from_send, fractions, per_watcher_p99, missed = [], [], [], [], 0
    for _, revisions, arrivals, _ in reports:
        arrived, fraction = delivery(revisions, arrivals, watched)
        got = [(t - acked, t - sent) for t, (_, sent, acked) in zip(arrived, watched) if t is not None]
        missed += len(arrived) - len(got)
        from_ack += [a for a, _ in got]
        from_send += [s for _, s in got]
        fractions.append(fraction)
        if got:
            per_watcher_p99.append(float(np.percentile([a for a, _ in got], 99)) * 1e3)
    alone_calls = [acked - sent for _, sent, acked in alone]
    watched_calls = [acked - sent for _, sent, acked in watched]
    slowdown = statistics.median(watched_calls) / statistics.median(alone_calls) - 1
    figures = {"watchers": WATCHERS, "never_reading_watchers": 1, "changes": CHANGES,
               "writer_target_hz": round(1 / PERIOD_S), "writer_hz": round(writer_hz, 1), "max_rate_hz": RATE_HZ,
               **ms_stats("delivery", from_ack),
               "delivery_ms_min": round(min(from_ack) * 1e3, 3),
               **ms_stats("delivery_from_send", from_send),
               "watcher_p99_ms_best_worst": [round(min(per_watcher_p99), 3), round(max(per_watcher_p99), 3)],
               "changes_never_delivered": missed,
               "seen_fraction_min": round(min(fractions), 3),
               "seen_fraction_mean": round(statistics.mean(fractions), 3),
               **ms_stats("writer_alone_set_body_poses", alone_calls),
               **ms_stats("writer_watched_set_body_poses", watched_calls),
               "slowdown_pct": round(100 * slowdown, 1),
               **(ms_stats("server_handler_alone", handler[:CHANGES]) if len(handler) == 2 * CHANGES else {}),
               **(ms_stats("server_handler_watched", handler[CHANGES:]) if len(handler) == 2 * CHANGES else {}),
               "never_reader_stream_active": stalled_active,
               "never_reader_snapshots_drained": len(drained),
               "never_reader_reached_final": bool(drained) and drained[-1] >= final,
               "client": "python-processes (one per reading watcher)"}
    return figures, server.exit_code
