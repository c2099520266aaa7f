"""Triangle meshes: packing into the API's MeshData, binary STL, and a few closed test shapes.

Vertices are (N, 3) in m; triangles are (M, 3) vertex indices, counter-clockwise seen from outside.
"""
from __future__ import annotations

import struct
from typing import Any, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspsim.v1 import common_pb2

# (vertices (N, 3) m: float64, or float32 as unpacked from the wire; triangles (M, 3) uint32)
Mesh = Tuple[NDArray[np.floating[Any]], NDArray[np.uint32]]


def pack_mesh(vertices: ArrayLike, triangles: ArrayLike) -> common_pb2.MeshData:
    """MeshData with vertices as float32 LE bytes and triangles as uint32 LE bytes (no range checks here)."""
    v = np.asarray(vertices, dtype="<f4")
    t = np.asarray(triangles, dtype="<u4")
    if v.ndim != 2 or v.shape[1] != 3 or t.ndim != 2 or t.shape[1] != 3:
        raise ValueError(f"mesh needs vertices (N, 3) and triangles (M, 3), got {v.shape} and {t.shape}")
    return common_pb2.MeshData(vertices=v.tobytes(), triangles=t.tobytes())


def unpack_mesh(msg: common_pb2.MeshData) -> Mesh:
    """(vertices (N, 3) float32 m, triangles (M, 3) uint32) of a MeshData message."""
    v = np.frombuffer(msg.vertices, dtype="<f4").reshape(-1, 3)
    t = np.frombuffer(msg.triangles, dtype="<u4").reshape(-1, 3)
    return v, t


def to_stl(vertices: ArrayLike, triangles: ArrayLike) -> bytes:
    """Binary STL of a mesh (80-byte header, uint32 count, 50 bytes per triangle with its unit normal)."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    corners = v[t]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    record = np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])
    body = np.zeros(len(t), dtype=record)
    body["normal"], body["corners"] = normals, corners
    return b"graspsim binary STL".ljust(80, b" ") + struct.pack("<I", len(t)) + body.tobytes()


def box_mesh(size: ArrayLike) -> Mesh:
    """Closed box of full edge lengths size (m), centred on the origin: 8 vertices, 12 triangles."""
    half = np.asarray(size, dtype=np.float64) / 2.0
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    triangles = np.array([
        [0, 1, 3], [0, 3, 2],  # -x
        [4, 6, 7], [4, 7, 5],  # +x
        [0, 4, 5], [0, 5, 1],  # -y
        [2, 3, 7], [2, 7, 6],  # +y
        [0, 2, 6], [0, 6, 4],  # -z
        [1, 5, 7], [1, 7, 3],  # +z
    ], dtype=np.uint32)
    return corners * half, triangles


def uv_sphere(radius: float, rings: int, segments: int) -> Mesh:
    """Closed latitude-longitude sphere (m): 2 + (rings-1)·segments vertices, 2·(rings-1)·segments triangles."""
    if rings < 2 or segments < 3:
        raise ValueError(f"uv_sphere needs rings >= 2 and segments >= 3, got {rings} and {segments}")
    theta = np.pi * np.arange(1, rings) / rings
    phi = 2.0 * np.pi * np.arange(segments) / segments
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    ring_points = np.stack([st * np.cos(phi), st * np.sin(phi), np.broadcast_to(ct, (rings - 1, segments))], axis=-1)
    vertices = np.vstack([[0.0, 0.0, 1.0], ring_points.reshape(-1, 3), [0.0, 0.0, -1.0]]) * float(radius)
    south = len(vertices) - 1

    def ring(i: int, j: NDArray[np.int64]) -> NDArray[np.int64]:
        return 1 + i * segments + j % segments

    j = np.arange(segments)
    faces = [np.stack([np.zeros_like(j), ring(0, j), ring(0, j + 1)], axis=1)]
    for i in range(rings - 2):
        a, b, c, d = ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)
        faces += [np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)]
    last = rings - 2
    faces.append(np.stack([np.full_like(j, south), ring(last, j + 1), ring(last, j)], axis=1))
    return vertices, np.vstack(faces).astype(np.uint32)
