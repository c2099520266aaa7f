"""One Parquet dataset per job: a directory with one file per task, <key>.parquet, written atomically (a hidden
temporary file renamed over it), so a task written twice leaves one file and never a torn one."""
from __future__ import annotations

import hashlib
import json
import os
import uuid
from pathlib import Path
from typing import Any, Dict, Iterable, List, Optional, Set, Union

import pyarrow as pa
import pyarrow.parquet as pq


def canonical_json(value: Any) -> str:
    """Sorted keys, no spaces: the same parameters give the same text (and key) whatever their order."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"))


def sha256_hex(*parts: object) -> str:
    h = hashlib.sha256()
    for part in parts:
        h.update(part if isinstance(part, bytes) else str(part).encode())
        h.update(b"\0")
    return h.hexdigest()


def write_task(dataset: Path, key: str, rows: List[Dict[str, Any]], schema: pa.Schema) -> Path:
    """Writes rows as dataset/<key>.parquet via a hidden temporary file and os.replace."""
    dataset.mkdir(parents=True, exist_ok=True)
    final = dataset / f"{key}.parquet"
    temporary = dataset / f".{key}.{uuid.uuid4().hex}.tmp"
    try:
        pq.write_table(pa.Table.from_pylist(rows, schema=schema), temporary)
        os.replace(temporary, final)
    finally:
        temporary.unlink(missing_ok=True)
    return final


def written_keys(dataset: Path, retry_errors: bool = False) -> Set[str]:
    """Keys whose file exists (resume skips them); with retry_errors, not those whose rows record an error."""
    if not dataset.is_dir():
        return set()
    keys = set()
    for path in dataset.glob("*.parquet"):
        if retry_errors and pq.read_table(path, columns=["error"])["error"].null_count != _rows(path):
            continue
        keys.add(path.stem)
    return keys


def _rows(path: Path) -> int:
    rows: int = pq.ParquetFile(path).metadata.num_rows
    return rows


def read_dataset(dataset: Union[str, "os.PathLike[str]"], columns: Optional[Iterable[str]] = None) -> pa.Table:
    """The whole dataset as one table (files in key order; hidden temporary files are ignored)."""
    files = sorted(Path(dataset).glob("*.parquet"))
    if not files:
        raise FileNotFoundError(f"no <key>.parquet files in {dataset}")
    return pa.concat_tables([pq.read_table(f, columns=list(columns) if columns else None) for f in files])
