"""map_scenes: any fn(client, item) over items, on a pool of ServerActors, results in input order."""
from __future__ import annotations

from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence

from graspsim.batch._pool import PoolOptions, progress_bar, ray_session, run_pool


class TaskError(RuntimeError):
    """fn raised on its worker ("Type: message"), or the item lost its worker max_attempts times."""


def map_scenes(fn: Callable[..., Any], items: Iterable[Any], *, workers: Optional[int] = None,
               address: Optional[str] = None, server: Optional[str] = None, compute_threads: Optional[int] = None,
               server_flags: Sequence[str] = (), progress: bool = True, return_exceptions: bool = False, timeout: float = 3600.0) -> List[Any]:
    """[fn(client, item) for item in items], each call on a ServerActor (a server of its own, a graspsim.Client
    of it); fn and its results must pickle (a module-level function or a lambda: Ray uses cloudpickle). An item
    whose worker died is run again on another. An item whose fn raised: TaskError in its place with
    return_exceptions, else the first one is raised once every item has run."""
    items = list(items)
    results: List[Any] = [None] * len(items)
    failed: Dict[int, TaskError] = {}
    bar = None

    def on_result(i: int, status: str, value: Any) -> None:
        if status == "ok":
            results[i] = value
        else:
            failed[i] = results[i] = TaskError(f"item {i}: {value}")
        if bar is not None:
            bar.update(1)

    try:
        with ray_session(address):
            bar = progress_bar(progress, len(items), 0, "items")
            run_pool([(fn, item) for item in items], on_result,
                     PoolOptions(workers, server, compute_threads, server_flags, None, timeout))
    finally:
        if bar is not None:
            bar.close()
    if failed and not return_exceptions:
        raise failed[min(failed)]
    return results
