"""import: robot files nobody here wrote, loaded as a user would — add_robot(path=...) — and with the loaders
users compare us with, on the same files in the same run.

Corpora (never vendored; tests/bench/run fetches them on first use):
  URDF  every .urdf of pybullet_data (the pybullet wheel): ~95 hand-made robots and objects + 1,000 random_urdfs
  MJCF  pybullet_data/mjcf/*.xml, and robosuite 1.5.2's models/assets/grippers/*.xml and robots/*/robot.xml
  SDF   every .sdf of pybullet_data
Each file goes through client.add_robot(scene, "robot", path=file) into a fresh scene (its meshes uploaded by
the client, as a user's would be). Peers: PyBullet (loadURDF with useFixedBase, loadSDF) and MuJoCo
(MjModel.from_xml_path) on the same files; "*_where_peer_loads" counts our loads among the files the peer loads.

panda_load_ms: franka_panda/panda.urdf with its meshes already in the scene, the AddRobot round trip (client
to client, the server parses the URDF and its 10 collision meshes), median of 20 with p10/p90; the robot is
removed between calls. panda_load_server_ms: the server's own time in those 20 handlers (its debug log).
panda_load_by_path_ms: add_robot(path=...) as a user calls it (read, resolve, hash, GetScene, AddRobot).
The server keeps meshes it parsed (by content hash, world/parsed_mesh_cache.h), so these are warm figures: the
corpus pass loaded the Panda before. panda_load_cold_ms: the first AddRobot of the Panda in a fresh server (its
10 meshes parsed in child processes), one per server, median of 5 servers.
pybullet_panda_load_ms: PyBullet's loadURDF of the same file in this process, for context.

Per failure, the file and the message go to build/bench/import_failures.txt (tab-separated: format, file,
whether the peer loads it, message), not to the JSON; stderr gets the failures grouped by message pattern.
"""
import collections
import contextlib
import glob
import os
import re
import time
from pathlib import Path

import graspsim
import numpy as np
from graspsim import _robot_files

from _harness import REPO, Server, log

REPEATS = 20
COLD_REPEATS = 5
ROBOSUITE = REPO / "build" / "bench-data" / "robosuite-1.5.2" / "robosuite" / "models" / "assets"
FAILURES = REPO / "build" / "bench" / "import_failures.txt"


def corpora():
    import pybullet_data
    data = Path(pybullet_data.getDataPath())
    urdf = sorted(Path(p) for p in glob.glob(str(data / "**" / "*.urdf"), recursive=True))
    sdf = sorted(Path(p) for p in glob.glob(str(data / "**" / "*.sdf"), recursive=True))
    mjcf = sorted((data / "mjcf").glob("*.xml"))
    if not ROBOSUITE.is_dir():
        raise RuntimeError(f"robosuite 1.5.2 not found at {ROBOSUITE}: tests/bench/run import fetches it")
    mjcf += sorted(ROBOSUITE.glob("grippers/*.xml")) + sorted(ROBOSUITE.glob("robots/*/robot.xml"))
    return data, {"urdf": urdf, "mjcf": mjcf, "sdf": sdf}


@contextlib.contextmanager
def quiet_stdout():
    """PyBullet prints its warnings on file descriptor 1, where our JSON goes: send them to /dev/null."""
    sys_out = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        os.dup2(sys_out, 1)
        os.close(devnull)
        os.close(sys_out)


PEER_WORKER = r"""
import os, sys
os.dup2(os.open(os.devnull, os.O_WRONLY), 1)  # PyBullet prints on fd 1
import mujoco, pybullet as p
fmt, out = sys.argv[1], open(sys.argv[2], "a")
client = p.connect(p.DIRECT)
for path in sys.stdin.read().splitlines():
    out.write(f"start\t{path}\n"); out.flush()
    try:
        if fmt == "urdf":
            p.loadURDF(path, useFixedBase=True, physicsClientId=client)
        elif fmt == "sdf":
            p.loadSDF(path, physicsClientId=client)
        else:
            mujoco.MjModel.from_xml_path(path)
        ok = True
    except Exception:  # pybullet.error, MuJoCo's ValueError
        ok = False
    p.resetSimulation(physicsClientId=client)
    out.write(f"{'ok' if ok else 'fail'}\t{path}\n"); out.flush()
"""


def peer_loads(files):
    """{file: True/False}: whether PyBullet (URDF, SDF) or MuJoCo (MJCF) loads it. The peers run in a child
    process that is restarted after a crash (PyBullet 3.2.7's loadSDF segfaults on
    gripper/wsg50_one_motor_gripper_free_base.sdf); the file it crashed on counts as not loaded."""
    import subprocess
    import sys
    import tempfile
    loads = {}
    for fmt, paths in files.items():
        remaining = [str(p) for p in paths]
        while remaining:
            with tempfile.NamedTemporaryFile("r", suffix=".peer") as results:
                subprocess.run([sys.executable, "-c", PEER_WORKER, fmt, results.name], input="\n".join(remaining),
                               text=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                started = None
                for line in results.read().splitlines():
                    state, path = line.split("\t", 1)
                    if state == "start":
                        started = path
                    else:
                        loads[Path(path)] = state == "ok"
                        started = None
            if started is not None:
                loads[Path(started)] = False
                log(f"peer crashed on {started}: counted as not loaded")
            remaining = [p for p in remaining if Path(p) not in loads]
    return loads


def cold_panda_load_s(panda: Path) -> float:
    """The first AddRobot of the Panda, meshes uploaded, in a server of its own: nothing parsed before."""
    with Server() as server, graspsim.connect(server.address) as client:
        scene_id = client.create_scene("import-panda-cold").id
        robot_files = _robot_files.collect(panda)
        _robot_files.upload_missing(client, scene_id, robot_files.files)
        t0 = time.perf_counter()
        client.add_robot(scene_id, "panda", urdf=robot_files.text)
        return time.perf_counter() - t0


def pybullet_panda_ms(panda: Path):
    import pybullet as p
    times = []
    with quiet_stdout():
        client = p.connect(p.DIRECT)
        for _ in range(REPEATS + 1):
            t0 = time.perf_counter()
            p.loadURDF(str(panda), useFixedBase=True, physicsClientId=client)
            times.append(time.perf_counter() - t0)
            p.resetSimulation(physicsClientId=client)
        p.disconnect(client)
    return times[1:]


def pattern(message: str) -> str:
    """A failure message with its particulars (quoted names, numbers, paths) blanked: the cause to group by."""
    first = message.strip().splitlines()[0] if message.strip() else "(no message)"
    first = re.sub(r"/\S+", "<path>", first)
    first = re.sub(r"'[^']*'|\"[^\"]*\"", "'…'", first)
    first = re.sub(r"-?\d+(\.\d+)?([eE][-+]?\d+)?", "N", first)
    return first[:160]


def spread(prefix, seconds):
    ms = np.asarray(seconds) * 1e3
    return {f"{prefix}_ms": round(float(np.median(ms)), 3), f"{prefix}_ms_p10": round(float(np.percentile(ms, 10)), 3),
            f"{prefix}_ms_p90": round(float(np.percentile(ms, 90)), 3)}


def run():
    data, files = corpora()
    load_before = round(os.getloadavg()[0], 2)
    total = sum(len(v) for v in files.values())
    log(f"peers: PyBullet on {len(files['urdf'])} URDF + {len(files['sdf'])} SDF, MuJoCo on {len(files['mjcf'])} MJCF")
    peer = peer_loads(files)
    figures, failures, warnings_total = {}, [], 0
    # debug log: the server's own time in each AddRobot handler (Server.handler_seconds)
    with Server("--log-level=debug") as server, graspsim.connect(server.address, call_timeout=120) as client:
        log(f"add_robot(path=...) of {total} files, each into a fresh scene")
        started = time.perf_counter()
        for fmt, paths in files.items():
            loaded = where_peer = 0
            for i, path in enumerate(paths):
                scene_id = client.create_scene(f"import-{fmt}-{i}").id
                try:
                    reply = client.add_robot(scene_id, "robot", path=path)
                    loaded += 1
                    where_peer += peer[path]
                    warnings_total += len(reply.warnings)
                except (graspsim.GraspsimError, FileNotFoundError, ValueError) as err:
                    message = err.message if isinstance(err, graspsim.GraspsimError) else f"client: {err}"
                    failures.append((fmt, path, peer[path], type(err).__name__, message))
                finally:
                    client.delete_scene(scene_id)
            peer_total = sum(peer[p] for p in paths)
            figures.update({f"{fmt}_total": len(paths), f"{fmt}_loaded": loaded,
                            f"{fmt}_load_rate": round(loaded / max(len(paths), 1), 4),
                            f"{fmt}_peer": "mujoco" if fmt == "mjcf" else "pybullet",
                            f"{fmt}_peer_loaded": peer_total, f"{fmt}_loaded_where_peer_loads": where_peer})
            if fmt == "urdf":
                random_paths = [p for p in paths if "random_urdfs" in p.parts]
                figures["urdf_random_total"] = len(random_paths)
                figures["urdf_random_loaded"] = len(random_paths) - sum(
                    1 for f in failures if f[0] == "urdf" and "random_urdfs" in f[1].parts)
            log(f"{fmt}: {loaded} / {len(paths)} loaded (peer {peer_total}); {time.perf_counter() - started:.0f} s")
        figures["warnings_total"] = warnings_total

        panda = data / "franka_panda" / "panda.urdf"
        scene_id = client.create_scene("import-panda").id
        robot_files = _robot_files.collect(panda)
        _robot_files.upload_missing(client, scene_id, robot_files.files)
        times, by_path = [], []
        for i in range(REPEATS + 1):  # the first call warms caches (the server's parsed meshes); not counted
            t0 = time.perf_counter()
            reply = client.add_robot(scene_id, "panda", urdf=robot_files.text)
            times.append(time.perf_counter() - t0)
            client.remove_body(scene_id, reply.robot.id)
        for i in range(REPEATS):  # the whole one-call path: read, resolve, hash, GetScene, AddRobot
            t0 = time.perf_counter()
            reply = client.add_robot(scene_id, "panda", path=panda)
            by_path.append(time.perf_counter() - t0)
            client.remove_body(scene_id, reply.robot.id)
        client.delete_scene(scene_id)
        figures.update(spread("panda_load", times[1:]))
        handler = server.handler_seconds("AddRobot")  # in call order: ..., warm-up, 20 timed, 20 by path
        if len(handler) >= 2 * REPEATS + 1:
            figures.update(spread("panda_load_server", handler[-2 * REPEATS:-REPEATS]))
        figures["panda_links"] = len(reply.bodies)
        figures.update(spread("panda_load_by_path", by_path))
        figures.update(spread("pybullet_panda_load", pybullet_panda_ms(panda)))
        figures["panda_repeats"] = REPEATS
    figures.update(spread("panda_load_cold", [cold_panda_load_s(panda) for _ in range(COLD_REPEATS)]))

    FAILURES.parent.mkdir(parents=True, exist_ok=True)
    with open(FAILURES, "w") as out:
        out.write("# format\tfile\tpeer loads it\terror\tmessage (tests/bench/run import)\n")
        for fmt, path, peer_ok, kind, message in failures:
            shown = str(path.relative_to(data)) if path.is_relative_to(data) else str(path.relative_to(REPO))
            out.write(f"{fmt}\t{shown}\t{peer_ok}\t{kind}\t{' | '.join(message.splitlines())}\n")
    groups = collections.Counter((f[0], pattern(f[4])) for f in failures)
    log(f"{len(failures)} failures ({FAILURES}), by cause:")
    for (fmt, cause), count in groups.most_common():
        log(f"  {count:5d}  {fmt}  {cause}")
    figures["failures_file"] = str(FAILURES.relative_to(REPO))
    figures["load_avg_1m"] = [load_before, round(os.getloadavg()[0], 2)]
    return figures, server.exit_code
