"""UploadFile's client stream: a header chunk, then the file's bytes in chunks."""
from __future__ import annotations

import hashlib
import os
from typing import Iterator, Tuple, Union

from graspsim.v1 import scene_pb2

FileData = Union[bytes, bytearray, memoryview, str, os.PathLike[str]]


def _pieces(data: FileData, chunk_size: int) -> Iterator[bytes]:
    """The file's bytes in pieces of at most chunk_size; data is bytes, or the path of a local file."""
    if isinstance(data, (bytes, bytearray, memoryview)):
        view = memoryview(data).cast("B")
        for start in range(0, len(view), chunk_size):
            yield bytes(view[start:start + chunk_size])
        return
    with open(data, "rb") as f:
        while piece := f.read(chunk_size):
            yield piece


def digest(data: FileData, chunk_size: int = 1 << 20) -> Tuple[int, str]:
    """(size in bytes, lowercase hex SHA-256) of bytes or of a local file."""
    sha, size = hashlib.sha256(), 0
    for piece in _pieces(data, chunk_size):
        sha.update(piece)
        size += len(piece)
    return size, sha.hexdigest()


def upload_chunks(scene_id: str, path: str, data: FileData, chunk_size: int) -> Iterator[scene_pb2.UploadFileChunk]:
    """The UploadFile request stream: the first message carries the header (scene, path, total size, SHA-256)
    and the first data piece; each next message one more piece of at most chunk_size bytes."""
    if chunk_size <= 0:
        raise ValueError(f"chunk_size must be > 0 bytes, got {chunk_size}")
    size, sha256 = digest(data, chunk_size)
    header = scene_pb2.UploadFileHeader(scene_id=scene_id, path=path, total_size=size, sha256=sha256)
    first = True
    for piece in _pieces(data, chunk_size):
        yield scene_pb2.UploadFileChunk(header=header, data=piece) if first else scene_pb2.UploadFileChunk(data=piece)
        first = False
    if first:
        yield scene_pb2.UploadFileChunk(header=header)
