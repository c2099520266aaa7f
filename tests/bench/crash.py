"""crash: kill -9 the server at random points during uploads, edits and long simulation runs, restart it on the
same data directory, and check that every acknowledged write is there and nothing half-written is visible.

Seeded (SEED): the workload, the kill delays and the upload sizes repeat; where the kill lands in the server's
work does not (threads and the disk decide). Three client threads work at once, each on scenes of its own, so
each thread has at most one request in flight when the server dies: after the restart that request's write may
be there or not (it was never acknowledged), but whole or not at all. Every GROUP iterations start on a new,
empty data directory, so the store also reopens after several crashes in a row.

What "partial" means per kind of write (docs/durability.md):
- upload: a file listed must have the exact size and SHA-256 of one that was sent;
- AddRobot: a robot listed must have all of its links and joints;
- SetBodyPoses: each request moves two static objects to the same x; both must show the same request's x;
- SetJointPositions: each request sets two joints of one robot to the same value; both must show it;
- StepSimulation: the scene's time is the acknowledged time, or at most the in-flight request's end.
"""
import hashlib
import random
import re
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path

import graspsim
from graspsim import meshes

from _harness import SERVER_BIN, log

SEED = 11
ITERATIONS = 100
GROUP = 10           # iterations per data directory
THREADS = 3
KILL_DELAY_S = (0.2, 2.0)
START_TIMEOUT_S = 60.0

ARM_URDF = """<?xml version="1.0"?>
<robot name="arm2">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="a"><inertial><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><box size="0.05 0.05 0.2"/></geometry></collision></link>
  <link name="b"><inertial><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><box size="0.05 0.05 0.2"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
"""
PG70_LINKS = 0  # links of the built-in PG70, learnt once from the server (learn_pg70())


class ServerProcess:
    """graspsim-server on a free port and a given data directory; killed with SIGKILL, stopped with SIGTERM."""

    def __init__(self, data_dir: str, log_path: Path, env=None):
        self.log_path = log_path
        offset = log_path.stat().st_size if log_path.exists() else 0
        started = time.perf_counter()
        with open(log_path, "ab") as out:
            self.process = subprocess.Popen([str(SERVER_BIN), "--listen=127.0.0.1:0", "--http-listen=off",
                                             f"--data-dir={data_dir}", "--log-level=info"],
                                            stdout=out, stderr=subprocess.STDOUT, env=env)
        deadline = time.monotonic() + START_TIMEOUT_S
        while True:
            text = log_path.read_bytes()[offset:].decode(errors="replace")
            found = re.search(r"msg=listening .*port=(\d+)", text)
            if found:
                break
            if self.process.poll() is not None or time.monotonic() > deadline:
                self.process.kill()
                raise RuntimeError(f"graspsim-server did not restart on {data_dir}:\n{text[-2000:]}")
            time.sleep(0.01)
        self.address = f"127.0.0.1:{found.group(1)}"
        self.client = graspsim.connect(self.address, call_timeout=60)
        self.client.list_scenes()  # serving, not only listening
        self.start_s = time.perf_counter() - started
        restored = re.search(r'msg="scenes restored" .*scenes=(\d+) ms=([\d.]+)', text)
        self.scenes_restored = int(restored.group(1)) if restored else -1
        self.restore_ms = float(restored.group(2)) if restored else -1.0

    def kill(self):
        self.client.close()
        self.process.send_signal(signal.SIGKILL)
        self.process.wait()

    def stop(self) -> int:
        self.client.close()
        self.process.send_signal(signal.SIGTERM)
        return self.process.wait(30)


class SceneModel:
    """What one thread knows of one of its scenes: acknowledged writes, and the one that may be in flight."""

    def __init__(self, kind: str, name: str):
        self.kind, self.name = kind, name   # kind: "edit" (objects, robots, poses, joints) or "sim" (stepped)
        self.id = None
        self.deleted = False
        self.files = {}       # path -> (size, sha256), acknowledged
        self.objects = set()  # acknowledged object names
        self.robots = {}      # name -> number of links
        self.pose_x = None    # the x both pose objects were last set to (acknowledged)
        self.joint_q = None
        self.time = 0.0       # acknowledged simulation time, s
        self.pending = None   # (kind, details) of the request in flight


class Worker(threading.Thread):
    def __init__(self, index: int, address: str, rng: random.Random, scenes: list, stats: dict):
        super().__init__(daemon=True)
        self.index, self.rng, self.scenes, self.stats = index, rng, scenes, stats
        self.client = graspsim.connect(address, call_timeout=60)
        self.stop_flag = False

    def run(self):
        try:
            while not self.stop_flag:
                self.work()
        except graspsim.GraspsimError:
            pass  # the server died: the pending write stays pending
        except Exception as err:  # noqa: BLE001 (the connection breaks in many ways when the server dies)
            if not isinstance(err, (ConnectionError, OSError)) and "UNAVAILABLE" not in str(err):
                log(f"worker {self.index}: {type(err).__name__}: {err}")
        finally:
            self.client.close()

    def work(self):
        live = [s for s in self.scenes if s.id and not s.deleted]
        if len(live) < 2 or self.rng.random() < 0.03:
            return self.create(self.rng.choice(["edit", "sim"]))
        scene = self.rng.choice(live)
        if scene.kind == "sim":
            op = self.rng.choices(["sim", "upload", "delete"], [6, 2, 0.3])[0]
        else:
            op = self.rng.choices(["poses", "joints", "upload", "object", "remove", "robot", "delete"],
                                  [5, 5, 3, 2, 1, 1, 0.3])[0]
        getattr(self, op)(scene)

    def acked(self, scene, kind):
        scene.pending = None
        self.stats[kind] = self.stats.get(kind, 0) + 1

    def create(self, kind):
        scene = SceneModel(kind, f"crash-{self.index}-{len(self.scenes)}")
        self.scenes.append(scene)
        scene.pending = ("create", None)
        scene.id = self.client.create_scene(scene.name).id
        self.acked(scene, "create")
        c = self.client
        if kind == "edit":
            for name in ("p1", "p2"):
                scene.pending = ("object", name)
                c.add_object(scene.id, name, box=[0.05, 0.05, 0.05], mass=0.1, is_static=True,
                             pose=[0, 0, 0.5, 1, 0, 0, 0])
                scene.objects.add(name)
                self.acked(scene, "object")
            scene.pending = ("robot", ("arm2", 3))
            c.add_robot(scene.id, "arm2", urdf=ARM_URDF, base_pose=[1, 0, 0, 1, 0, 0, 0])
            scene.robots["arm2"] = 3
            self.acked(scene, "robot")
        else:
            for name, kwargs in (("table", {}), ("cube", {"pose": [0, 0, 0.8, 1, 0, 0, 0]})):
                scene.pending = ("object", name)
                c.add_object(scene.id, name, builtin="table" if name == "table" else "cube_5cm", **kwargs)
                scene.objects.add(name)
                self.acked(scene, "object")

    def upload(self, scene):
        large = self.rng.random() < 0.08
        size = self.rng.randint(8 << 20, 24 << 20) if large else self.rng.randint(1, 200_000)
        data = self.rng.randbytes(size)
        path = f"f{self.rng.getrandbits(40):x}.bin"
        entry = (size, hashlib.sha256(data).hexdigest())
        scene.pending = ("upload", (path, entry))
        self.client.upload_file(scene.id, path, data)
        scene.files[path] = entry
        self.acked(scene, "upload_large" if large else "upload")

    def poses(self, scene):
        x = round(self.rng.uniform(-1, 1), 6)
        scene.pending = ("poses", x)
        self.client.set_body_poses(scene.id, {"p1": [x, 0, 0.5, 1, 0, 0, 0], "p2": [x, 1, 0.5, 1, 0, 0, 0]})
        scene.pose_x = x
        self.acked(scene, "poses")

    def joints(self, scene):
        q = round(self.rng.uniform(-0.9, 0.9), 6)
        scene.pending = ("joints", q)
        self.client.set_joint_positions(scene.id, {"arm2/j1": q, "arm2/j2": q})
        scene.joint_q = q
        self.acked(scene, "joints")

    def object(self, scene):
        name = f"o{self.rng.getrandbits(32):x}"
        scene.pending = ("object", name)
        self.client.add_object(scene.id, name, sphere=0.02, mass=0.1, is_static=True, pose=[0, 2, 0.5, 1, 0, 0, 0])
        scene.objects.add(name)
        self.acked(scene, "object")

    def remove(self, scene):
        extra = sorted(scene.objects - {"p1", "p2"})
        if not extra:
            return self.object(scene)
        name = self.rng.choice(extra)
        scene.pending = ("remove", name)
        self.client.remove_body(scene.id, name)
        scene.objects.discard(name)
        self.acked(scene, "remove")

    def robot(self, scene):
        name = f"g{self.rng.getrandbits(32):x}"
        scene.pending = ("robot", (name, PG70_LINKS))
        reply = self.client.add_robot(scene.id, name, builtin="schunk_pg70",
                                      base_pose=[0, -1, 1, 0, 1, 0, 0])
        scene.robots[name] = len(reply.bodies)
        assert len(reply.bodies) == PG70_LINKS
        self.acked(scene, "robot")

    def sim(self, scene):
        duration = self.rng.choice([0.05, 0.2, 1.0, 3.0])  # s of simulated time; 3 s is a long job
        scene.pending = ("sim", duration)
        reply = self.client.step_simulation(scene.id, duration)
        scene.time = reply.time
        self.acked(scene, "step")

    def delete(self, scene):
        scene.pending = ("delete", None)
        self.client.delete_scene(scene.id)
        scene.deleted = True
        self.acked(scene, "delete")


class GraspPlanner(threading.Thread):
    """Plans one grasp set (the PG70 on a box of a new size, ~1 s) while the workers write: grasp sets have a store
    of their own (server/src/grasp/store.cpp), counted apart (grasp_sets_lost)."""

    def __init__(self, address: str, rng: random.Random, grasp_sets: list, stats: dict):
        super().__init__(daemon=True)
        self.address, self.size, self.grasp_sets, self.stats = address, round(rng.uniform(0.04, 0.06), 6), grasp_sets, stats
        self.stop_flag = False

    def run(self):
        try:
            with graspsim.connect(self.address, call_timeout=60) as client:
                set_id = client.plan_grasps("schunk_pg70", mesh=meshes.box_mesh((self.size, 0.05, 0.06)),
                                            spacing=0.03, progress=False).set_id
            self.grasp_sets.append(set_id)
            self.stats["grasp_set"] = self.stats.get("grasp_set", 0) + 1
        except Exception:  # noqa: BLE001 (the server died first: never acknowledged)
            pass


class Load:
    """One iteration's clients: THREADS workers, each on its own scenes, and one grasp set planned meanwhile."""

    def __init__(self, address: str, rng: random.Random, scenes: list, grasp_sets: list, stats: dict):
        self.threads = [Worker(i, address, random.Random(rng.getrandbits(64)), scenes[i], stats)
                        for i in range(THREADS)]
        self.threads.append(GraspPlanner(address, rng, grasp_sets, stats))
        for thread in self.threads:
            thread.start()

    def stop(self):  # once the server is dead
        for thread in self.threads:
            thread.stop_flag = True
        for thread in self.threads:
            thread.join(60)


def check(client, scenes: list, grasp_sets: list, counts: dict) -> None:
    """verify() for each thread's scenes; then every acknowledged grasp set must be there (a lost one is counted
    once in grasp_sets_lost and forgotten)."""
    for thread_scenes in scenes:
        verify(client, thread_scenes, counts)
    for set_id in list(grasp_sets):
        try:
            client.get_grasp_set(set_id)
        except graspsim.NotFound:
            counts["grasp_sets_lost"] = counts.get("grasp_sets_lost", 0) + 1
            grasp_sets.remove(set_id)


def verify(client, scenes, counts) -> None:
    """Compares the restarted server with what the threads know; counts lost and partial writes; then takes
    what the server shows as the new acknowledged state (an in-flight write that landed is now simply there)."""
    by_id = {s.id: s for s in client.list_scenes()}

    def lost(what):
        counts["acknowledged_lost"] += 1
        log(f"LOST: {what}")

    def partial(what):
        counts["partial_visible"] += 1
        log(f"PARTIAL: {what}")

    def unacknowledged():  # the write in flight landed: allowed, counted to show the cut can fall after a commit
        counts["unacknowledged_seen"] = counts.get("unacknowledged_seen", 0) + 1

    for scene in scenes:
        pending_kind, detail = scene.pending or (None, None)
        scene.pending = None
        if scene.id is None:
            # CreateScene in flight: a scene of this name may exist now; adopt it if so.
            ids = [i for i, summary in by_id.items() if summary.name == scene.name]
            scene.id = ids[0] if ids else None
            scene.deleted = not ids
            if not ids:
                continue
            unacknowledged()
        if scene.deleted:
            if scene.id in by_id:
                lost(f"{scene.id} deleted, but back after the restart")
            continue
        if scene.id not in by_id:
            if pending_kind == "delete":
                scene.deleted = True
                unacknowledged()
            else:
                lost(f"{scene.id} ({scene.name}) is gone")
                scene.deleted = True
            continue
        if by_id[scene.id].name != scene.name:
            lost(f"{scene.id}: name {by_id[scene.id].name!r}, not {scene.name!r}")
        if pending_kind == "delete":  # the delete did not land: the scene stays, and the thread may go on
            pass
        view = client.get_scene(scene.id)
        counts["scenes_checked"] += 1
        # Files.
        files = {f.path: (f.size, f.sha256) for f in view.files}
        for path, entry in scene.files.items():
            if files.get(path) != entry:
                lost(f"{scene.id}: file {path} {entry} -> {files.get(path)}")
        for path, entry in files.items():
            if path in scene.files:
                continue
            if pending_kind == "upload" and detail == (path, entry):
                scene.files[path] = entry
                unacknowledged()
            else:
                partial(f"{scene.id}: file {path} {entry} was never sent whole")
        # Objects and robots.
        bodies = {b.id for b in view.bodies}
        robots = {r.id: r for r in view.robots}
        objects = {b for b in bodies if "/" not in b}
        for name in scene.objects - objects:
            if pending_kind == "remove" and detail == name:
                unacknowledged()
            else:
                lost(f"{scene.id}: object {name} is gone")
        for name in objects - scene.objects:
            if pending_kind == "object" and detail == name:
                unacknowledged()
            else:
                partial(f"{scene.id}: object {name} was never added")
        scene.objects = objects
        for name, links in list(scene.robots.items()):
            if name not in robots:
                lost(f"{scene.id}: robot {name} is gone")
                del scene.robots[name]
        for name, robot in robots.items():
            expected = scene.robots.get(name)
            if expected is None:
                if pending_kind == "robot" and detail[0] == name:
                    expected = detail[1]
                    scene.robots[name] = expected
                    unacknowledged()
                else:
                    partial(f"{scene.id}: robot {name} was never added")
                    continue
            links = [b for b in bodies if b.startswith(name + "/")]
            if len(links) != expected or len(robot.body_ids) != expected or not set(robot.body_ids) <= bodies:
                partial(f"{scene.id}: robot {name} has {len(links)} of its {expected} links")
        # Poses, joints, time.
        if scene.kind == "edit" and {"p1", "p2"} <= objects:
            poses = client.get_body_poses(scene.id, ["p1", "p2"])
            x1, x2 = poses["p1"].position[0], poses["p2"].position[0]
            if x1 != x2:
                partial(f"{scene.id}: p1.x {x1} and p2.x {x2} differ (half of a SetBodyPoses)")
            allowed = {0.0 if scene.pose_x is None else scene.pose_x}
            if pending_kind == "poses":
                allowed.add(detail)
            if x1 not in allowed:
                lost(f"{scene.id}: p1.x {x1}, acknowledged {scene.pose_x}")
            elif x1 != (scene.pose_x or 0.0):
                unacknowledged()
            scene.pose_x = x1
        if scene.kind == "edit" and "arm2" in robots:
            joints = client.get_joint_positions(scene.id, ["arm2/j1", "arm2/j2"])
            q1, q2 = joints["arm2/j1"], joints["arm2/j2"]
            if q1 != q2:
                partial(f"{scene.id}: j1 {q1} and j2 {q2} differ (half of a SetJointPositions)")
            allowed = {0.0 if scene.joint_q is None else scene.joint_q}
            if pending_kind == "joints":
                allowed.add(detail)
            if q1 not in allowed:
                lost(f"{scene.id}: j1 {q1}, acknowledged {scene.joint_q}")
            elif q1 != (scene.joint_q or 0.0):
                unacknowledged()
            scene.joint_q = q1
        if scene.kind == "sim":
            t = view.summary.time
            upper = scene.time + (detail if pending_kind == "sim" else 0.0) + 1e-9
            if t < scene.time - 1e-9:
                lost(f"{scene.id}: time {t} s, acknowledged {scene.time} s")
            elif t > upper:
                partial(f"{scene.id}: time {t} s beyond the acknowledged {scene.time} s + the run in flight")
            elif t > scene.time + 1e-9:
                unacknowledged()
            scene.time = t


def stop_last(server) -> None:
    """A run's last server stops with SIGTERM and must exit 0."""
    code = server.stop() if server else 0
    if code != 0:
        raise RuntimeError(f"the last server exited with {code} on SIGTERM")


def kill_left(server) -> None:
    """After a run that failed: no server left running."""
    if server and server.process.poll() is None:
        server.process.kill()


def learn_pg70(client) -> None:
    """The number of links of the built-in PG70, which the robot checks expect (asked once)."""
    global PG70_LINKS
    if not PG70_LINKS:
        probe = client.create_scene("probe").id
        PG70_LINKS = len(client.add_robot(probe, "g", builtin="schunk_pg70").bodies)
        client.delete_scene(probe)


def crash_iterations(iterations: int, seed: int, group: int = GROUP) -> dict:
    """Runs the crash test; returns its figures. Used by run() and by tests/python/test_durability.py."""
    rng = random.Random(seed)
    counts = {"acknowledged_lost": 0, "partial_visible": 0, "scenes_checked": 0, "unacknowledged_seen": 0,
              "grasp_sets_lost": 0}
    writes = {}
    restart_s, restore_ms, delays = [], [], []
    log_path = Path(tempfile.mkstemp(prefix="graspsim-crash-", suffix=".log")[1])
    data_dir, server, scenes = None, None, None
    try:
        for iteration in range(iterations):
            if iteration % group == 0:
                if server:
                    server.stop()
                if data_dir:
                    shutil.rmtree(data_dir, ignore_errors=True)
                data_dir = tempfile.mkdtemp(prefix="graspsim-crash-data-")
                server = ServerProcess(data_dir, log_path)
                learn_pg70(server.client)
                scenes, grasp_sets = [[] for _ in range(THREADS)], []
            load = Load(server.address, rng, scenes, grasp_sets, writes)
            delay = rng.uniform(*KILL_DELAY_S)
            delays.append(delay)
            time.sleep(delay)
            server.kill()
            load.stop()
            server = ServerProcess(data_dir, log_path)
            restart_s.append(server.start_s)
            restore_ms.append(server.restore_ms)
            check(server.client, scenes, grasp_sets, counts)
            log(f"iteration {iteration + 1}/{iterations}: killed after {delay:.2f} s, restart {server.start_s:.2f} s,"
                f" {server.scenes_restored} scenes; lost {counts['acknowledged_lost']},"
                f" partial {counts['partial_visible']}")
        stop_last(server)
    finally:
        kill_left(server)
        if data_dir:
            shutil.rmtree(data_dir, ignore_errors=True)
    log_path.unlink()
    restart_s.sort()
    return {"iterations": iterations, "seed": seed, "threads": THREADS, "acknowledged_lost": counts["acknowledged_lost"],
            "partial_visible": counts["partial_visible"], "scenes_checked": counts["scenes_checked"],
            "unacknowledged_seen": counts["unacknowledged_seen"], "grasp_sets_lost": counts["grasp_sets_lost"],
            "acknowledged_writes": dict(sorted(writes.items())),
            "restart_s_p50": round(restart_s[len(restart_s) // 2], 3), "restart_s_max": round(restart_s[-1], 3),
            "restore_ms_max": round(max(restore_ms), 1),
            "kill_delay_s": [round(min(delays), 2), round(max(delays), 2)]}


def run():
    import power_cut  # tests/bench/power_cut.py: the same workload and checks, with power cuts instead of kill -9
    return {**crash_iterations(ITERATIONS, SEED), **power_cut.power_cut_iterations(power_cut.ITERATIONS, SEED)}, 0
