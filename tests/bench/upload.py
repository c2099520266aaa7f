"""upload: chunked UploadFile of a 32 MiB file in 1 MiB chunks, and AddObject of a 200k-triangle STL mesh_file
(server-side parse via Assimp), against the same mesh sent inline (no parse) to show what the parse costs.

Three throughputs on the same random bytes (random, so nothing on the way can compress them), median of 5:
  upload_mib_per_s            client.upload_file as a user calls it: the client hashes the file, then streams it
  upload_prehashed_mib_per_s  the raw stub with the SHA-256 computed beforehand: transfer + the server's own check
  sha256_mib_per_s            hashlib.sha256 over the same bytes in this process, for context
"""
import hashlib
import os
import statistics
import time

import graspsim
import numpy as np
from graspsim import meshes
from graspsim.v1 import scene_pb2, scene_pb2_grpc

from _harness import Server, channel, log

MIB = 1 << 20
FILE_BYTES = 32 * MIB
CHUNK_BYTES = MIB
REPEATS = 5
SPHERE = dict(radius=0.05, rings=201, segments=500)  # 2·(rings-1)·segments = 200,000 triangles
MESH_MASS = 0.5                                      # kg


def timed(action) -> float:
    t0 = time.perf_counter()
    action()
    return time.perf_counter() - t0


def prehashed_chunks(scene_id: str, path: str, data: bytes, sha256: str):
    view = memoryview(data)
    header = scene_pb2.UploadFileHeader(scene_id=scene_id, path=path, total_size=len(data), sha256=sha256)
    yield scene_pb2.UploadFileChunk(header=header, data=bytes(view[:CHUNK_BYTES]))
    for start in range(CHUNK_BYTES, len(data), CHUNK_BYTES):
        yield scene_pb2.UploadFileChunk(data=bytes(view[start:start + CHUNK_BYTES]))


def mib_per_s(seconds) -> float:
    return round(FILE_BYTES / MIB / statistics.median(seconds), 1)


def run():
    data = os.urandom(FILE_BYTES)
    sha256 = hashlib.sha256(data).hexdigest()
    with Server() as server, graspsim.connect(server.address) as client:
        scene_id = client.create_scene("upload").id
        stub = scene_pb2_grpc.SceneServiceStub(channel(server.address))
        client.upload_file(scene_id, "warmup.bin", data[:4 * MIB], chunk_size=CHUNK_BYTES)

        log(f"sha256, client upload, prehashed upload: {REPEATS} × {FILE_BYTES // MIB} MiB each")
        hashing = [timed(lambda: hashlib.sha256(data).hexdigest()) for _ in range(REPEATS)]
        uploads, prehashed = [], []
        for _ in range(REPEATS):
            uploads.append(timed(lambda: client.upload_file(scene_id, "blob.bin", data, chunk_size=CHUNK_BYTES)))
            prehashed.append(timed(lambda: stub.UploadFile(prehashed_chunks(scene_id, "blob.bin", data, sha256),
                                                           timeout=60)))
        info = {f.path: f for f in client.get_scene(scene_id).files}["blob.bin"]
        if (info.size, info.sha256) != (FILE_BYTES, sha256):  # a figure of a broken upload is no figure
            raise RuntimeError(f"server holds blob.bin as {info.size} bytes, sha256 {info.sha256}")

        vertices, triangles = meshes.uv_sphere(**SPHERE)
        stl = meshes.to_stl(vertices, triangles)
        client.upload_file(scene_id, "meshes/sphere.stl", stl, chunk_size=CHUNK_BYTES)
        inertia = np.eye(3) * 0.4 * MESH_MASS * SPHERE["radius"] ** 2  # solid sphere, kg m²
        log(f"AddObject mesh_file with {len(triangles)} triangles ({len(stl) / MIB:.1f} MiB STL): {REPEATS} times")
        add_ms, counts = [], set()
        for i in range(REPEATS):
            t0 = time.perf_counter()
            body = client.add_object(scene_id, f"sphere{i}", mesh_file="meshes/sphere.stl", mass=MESH_MASS,
                                     inertia=inertia, pose=[0.2 * i, 0, 1, 1, 0, 0, 0])
            add_ms.append((time.perf_counter() - t0) * 1e3)
            counts.add(body.triangle_count)
        # The same mesh sent inline (packed arrays, no file, no Assimp): what AddObject costs besides the parse.
        inline_ms = []
        for i in range(REPEATS):
            t0 = time.perf_counter()
            client.add_object(scene_id, f"inline{i}", mesh=(vertices, triangles), mass=MESH_MASS, inertia=inertia,
                              pose=[0.2 * i, 0.5, 1, 1, 0, 0, 0])
            inline_ms.append((time.perf_counter() - t0) * 1e3)

    figures = {"file_mib": FILE_BYTES // MIB, "chunk_mib": CHUNK_BYTES // MIB, "repeats": REPEATS,
               "upload_mib_per_s": mib_per_s(uploads),
               "upload_mib_per_s_min_max": [mib_per_s([max(uploads)]), mib_per_s([min(uploads)])],
               "upload_prehashed_mib_per_s": mib_per_s(prehashed),
               "sha256_mib_per_s": mib_per_s(hashing),
               "mesh_triangles": len(triangles), "mesh_stl_mib": round(len(stl) / MIB, 2),
               "mesh_triangles_on_server": sorted(counts),
               "add_object_mesh_ms_p50": round(statistics.median(add_ms), 1),
               "add_object_mesh_ms_each": [round(ms, 1) for ms in add_ms],
               "add_object_inline_mesh_ms_p50": round(statistics.median(inline_ms), 1),
               "client": "python, one thread"}
    return figures, server.exit_code
