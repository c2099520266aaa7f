"""Runs work items on a pool of ServerActors: one item in flight per actor; an item whose actor (or its server)
died is resubmitted to another and a replacement actor is started; results are handed back as they come."""
from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
import uuid
from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple

import ray
from ray.exceptions import NodeDiedError, ObjectLostError, RayActorError, RayTaskError, WorkerCrashedError

from graspsim import _progress
from graspsim.batch._server import ServerActor

if TYPE_CHECKING:
    from tqdm import tqdm

# What a lost actor looks like from the driver: the actor process died (ray.kill, a crash, its node went away).
LOST = (RayActorError, WorkerCrashedError, ObjectLostError, NodeDiedError)
ACTOR_PREFIX = "graspsim-batch-"


def init_ray(address: Optional[str] = None, num_cpus: Optional[int] = None) -> bool:
    """Uses Ray as it is when already initialised; else joins the cluster at `address`, or (None) starts a local
    Ray. Returns True when this call started or joined it (the caller then shuts it down)."""
    if ray.is_initialized():
        return False
    if address:
        ray.init(address=address)
    else:
        ray.init(num_cpus=num_cpus, include_dashboard=False)
    return True


def default_workers(threads: int) -> int:
    """As many actors as the cluster's CPUs hold, `threads` CPUs each."""
    return max(1, int(ray.cluster_resources().get("CPU", 1)) // max(1, threads))


@dataclass
class PoolOptions:
    """How the actors are made: server binary, --compute-threads, extra server flags, and where their data dirs
    go (store_dir: kept, one worker-<n> per actor; None: a temporary root, removed at the end)."""
    workers: Optional[int] = None
    server: Optional[str] = None
    compute_threads: Optional[int] = None
    server_flags: Sequence[str] = ()
    store_dir: Optional[str] = None
    call_timeout: float = 3600.0
    max_attempts: int = 3  # an item whose actor dies this many times is reported as an error
    job: str = field(default_factory=lambda: uuid.uuid4().hex[:8])


@dataclass
class PoolStats:
    workers: int = 0
    retried: int = 0      # items resubmitted after their actor died
    replaced: int = 0     # actors started to replace dead ones
    stores: List[str] = field(default_factory=list)  # data dirs of the actors (kept only with store_dir)


def run_pool(calls: Sequence[Tuple[Any, ...]], on_result: Callable[[int, str, object], None],
             options: PoolOptions) -> PoolStats:
    """calls[i] = (fn, item, *args): actor.run(fn, item, *args) → fn(client, item, *args) on an actor.
    on_result(i, "ok" | "error", value) once per call, in completion order."""
    stats = PoolStats()
    if not calls:
        return stats
    threads = options.compute_threads or 1
    if options.server and os.path.isfile(options.server):
        options.server = os.path.abspath(options.server)  # the actors' working directory is not the driver's
    n = min(len(calls), options.workers or default_workers(threads))
    root = os.path.abspath(options.store_dir) if options.store_dir else \
        os.path.join(tempfile.gettempdir(), ACTOR_PREFIX + options.job)
    actors: List[Any] = []  # ray actor handles of ServerActor
    counter = [0]

    def start_actor() -> Any:
        counter[0] += 1
        name = f"{ACTOR_PREFIX}{options.job}-{counter[0]}"
        data_dir = os.path.join(root, f"worker-{counter[0]}")
        if options.store_dir is not None:
            stats.stores.append(data_dir)
        actor = ServerActor.options(name=name, num_cpus=threads).remote(
            options.server, options.compute_threads, data_dir, tuple(options.server_flags), options.call_timeout,
            options.store_dir is not None)
        actors.append(actor)
        return actor

    try:
        idle = [start_actor() for _ in range(n)]
        ray.get([a.info.remote() for a in idle])  # a server that cannot start fails the job here, once
        stats.workers = n
        inflight: Dict[Any, Tuple[Any, int]] = {}  # object ref -> (actor, call index)
        pending, attempts = deque(range(len(calls))), [0] * len(calls)
        while pending or inflight:
            while idle and pending:
                actor, i = idle.pop(), pending.popleft()
                fn, item, *args = calls[i]
                inflight[actor.run.remote(fn, item, *args)] = (actor, i)
            ready, _ = ray.wait(list(inflight), num_returns=1)
            actor, i = inflight.pop(ready[0])
            try:
                status, value = ray.get(ready[0])
            except LOST as err:
                status, value = "lost", f"{type(err).__name__}: {err}"
            except RayTaskError as err:  # the actor's own code failed, not the item's function
                status, value = "error", str(err)
            if status != "lost":
                idle.append(actor)
                on_result(i, status, value)
                continue
            attempts[i] += 1
            stats.retried += 1
            _kill(actor)
            actors.remove(actor)
            idle.append(start_actor())
            stats.replaced += 1
            if attempts[i] >= options.max_attempts:
                on_result(i, "error", f"lost its worker {attempts[i]} times, last: {value}")
            else:
                pending.appendleft(i)
    finally:
        _stop_all(actors)
        if options.store_dir is None:
            shutil.rmtree(root, ignore_errors=True)  # this node's dirs, killed actors' too
    return stats


def _kill(actor: Any) -> None:
    try:
        ray.kill(actor, no_restart=True)
    except Exception:  # noqa: BLE001 - already gone
        pass


def _stop_all(actors: List[Any]) -> None:
    refs: List[Any] = []
    for actor in actors:
        try:
            refs.append(actor.stop.remote())
        except Exception:  # noqa: BLE001
            pass
    for ref in refs:
        try:
            ray.get(ref, timeout=60)
        except Exception:  # noqa: BLE001 - dead actors: their servers got SIGTERM with them
            pass
    for actor in actors:
        _kill(actor)


@contextlib.contextmanager
def ray_session(address: Optional[str] = None, needed: bool = True) -> Iterator[None]:
    """init_ray for the length of a job (not when nothing is `needed`); shut down at its end only if the job
    started or joined it."""
    started = needed and init_ray(address)
    try:
        yield
    finally:
        if started:
            ray.shutdown()


def progress_bar(enabled: bool, total: int, initial: int, desc: str) -> tqdm[Any]:
    """The tqdm bar of a whole job, on the driver's stderr; it stays there as the job's summary."""
    return _progress.progress_bar(enabled, total, desc, "task", leave=True, initial=initial)
