"""What a batch job did: counts, time, where its dataset is."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Dict, List

if TYPE_CHECKING:
    from graspsim.batch._pool import PoolStats


@dataclass
class BatchSummary:
    """tasks: every task of the job; skipped: found written at the start (resume); done: written by this run
    (errors included); errors: tasks whose row records an error; retried: resubmissions after a worker died;
    replaced: workers started in place of dead ones; seconds: the whole call, Ray and worker start included."""
    objects: int = 0
    hands: int = 0
    tasks: int = 0
    skipped: int = 0
    done: int = 0
    errors: int = 0
    retried: int = 0
    replaced: int = 0
    workers: int = 0
    seconds: float = 0.0
    dataset: str = ""
    stores: List[str] = field(default_factory=list)  # each worker's server data dir, kept with store_dir only

    def add_pool(self, stats: PoolStats) -> None:
        self.workers, self.retried, self.replaced, self.stores = stats.workers, stats.retried, stats.replaced, \
            list(stats.stores)

    def as_dict(self) -> Dict[str, Any]:
        return dataclasses.asdict(self)
