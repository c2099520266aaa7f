"""The power-cut half of the crash benchmark (docs/durability.md, "The power-cut test"): the server runs with the
injector tests/stress/power_cut_shim.c preloaded, which records what of its data directory fsync has made durable;
after SIGKILL, cut() rebuilds the directory as a power cut would have left it (every file as of its last fsync,
every directory's entries as of its last fsync), and the server restarts on that. kill -9 alone never shows a
missing fsync: the page cache outlives the process.

Run by crash.py's run() after the kill -9 iterations (the same workload and checks: crash.Worker, crash.verify);
cut() and shim_env() are also used by tests/python/test_power_cut_shim.py.
"""
import os
import random
import shutil
import tempfile
import time
from pathlib import Path

import crash
from _harness import REPO, log

SHIM = Path(os.environ.get("GRASPSIM_POWER_CUT_SHIM", REPO / "build" / "lib" / "libgraspsim_power_cut.so"))
ITERATIONS = 30
GROUP = 10  # iterations per fresh data directory, as in crash.py


def shim_env(data_dir, state_dir, rule: str = "posix") -> dict:
    """The environment of a process whose writes under data_dir are to be cut (state_dir: the shim's record, an
    existing directory outside data_dir). rule: "posix" (directory entries durable at the directory's fsync),
    "journal" (at any fsync) or "nosync" (a disk that ignores flushes: nothing becomes durable)."""
    if not SHIM.is_file():
        raise RuntimeError(f"{SHIM} not found: build the graspsim_power_cut target (make build)")
    return {**os.environ, "LD_PRELOAD": str(SHIM), "GRASPSIM_POWER_CUT_DIR": os.path.realpath(data_dir),
            "GRASPSIM_POWER_CUT_STATE": os.path.realpath(state_dir), "GRASPSIM_POWER_CUT_RULE": rule}


def cut(data_dir, state_dir, out_dir) -> None:
    """Builds out_dir (new) as the power cut would leave data_dir, from the shim's record in state_dir. Run it only
    when no process writes under data_dir any more (after SIGKILL)."""
    data_dir, state = Path(os.path.realpath(data_dir)), Path(state_dir)
    # Inodes the process never changed nor unlinked have no copy in the record: their live file is their content.
    live = {}
    for root, _, names in os.walk(data_dir):
        for name in names:
            st = os.lstat(Path(root) / name)
            live[f"{st.st_dev}-{st.st_ino}-0"] = Path(root) / name
    st = os.stat(data_dir)

    def build(key: str, out: Path):
        out.mkdir()
        listing = state / "dirs" / key
        if not listing.exists():
            if key.endswith("-0"):
                raise RuntimeError(f"power cut: no record of the directory {key} that existed at start")
            return  # created, never fsync'ed: empty
        for line in listing.read_text().splitlines():
            kind, entry, name = line.split(" ", 2)
            if kind == "d":
                build(entry, out / name)
                continue
            copy = state / "inodes" / entry
            if copy.exists():
                shutil.copyfile(copy, out / name)
            elif entry.endswith("-0"):
                if entry not in live:
                    raise RuntimeError(f"power cut: {name} ({entry}) is neither recorded nor live")
                shutil.copyfile(live[entry], out / name)
            else:
                (out / name).touch()  # created, never fsync'ed: empty

    build(f"{st.st_dev}-{st.st_ino}-0", Path(out_dir))


class Shimmed:
    """The directory watched and the shim's record of it, in one scratch directory; cut() moves on to the next.
    The server's --data-dir is its subdirectory "store", which the first server creates, as on a first start."""

    def __init__(self, scratch: Path, rule: str):
        self.scratch, self.rule, self.n = scratch, rule, 0
        self.data = scratch / "data-0"
        self.state = scratch / "state-0"
        self.data.mkdir()
        self.state.mkdir()

    @property
    def store(self) -> str:
        return str(self.data / "store")

    def env(self):
        return shim_env(self.data, self.state, self.rule)

    def cut(self):
        self.n += 1
        data, state = self.scratch / f"data-{self.n}", self.scratch / f"state-{self.n}"
        cut(self.data, self.state, data)
        state.mkdir()
        shutil.rmtree(self.data)
        shutil.rmtree(self.state)
        self.data, self.state = data, state


def power_cut_iterations(iterations: int, seed: int, group: int = GROUP, rule: str = "posix") -> dict:
    """The crash test with power cuts instead of kill -9; returns its figures (keys power_cut_*)."""
    rng = random.Random(seed)
    counts = {"acknowledged_lost": 0, "partial_visible": 0, "scenes_checked": 0, "unacknowledged_seen": 0,
              "grasp_sets_lost": 0}
    writes, opened, failed = {}, 0, 0
    scratch = Path(tempfile.mkdtemp(prefix="graspsim-power-cut-"))
    log_path = scratch / "server.log"
    dirs, server, scenes = None, None, None
    try:
        for iteration in range(iterations):
            if iteration % group == 0 or server is None:
                if server:
                    server.stop()
                if dirs:
                    shutil.rmtree(dirs.scratch)
                dirs = Shimmed(Path(tempfile.mkdtemp(dir=scratch)), rule)
                server = crash.ServerProcess(dirs.store, log_path, env=dirs.env())
                crash.learn_pg70(server.client)
                scenes, grasp_sets = [[] for _ in range(crash.THREADS)], []
            load = crash.Load(server.address, rng, scenes, grasp_sets, writes)
            delay = rng.uniform(*crash.KILL_DELAY_S)
            time.sleep(delay)
            server.kill()  # the power cut: nothing of the process survives, and cut() drops what was not synced
            load.stop()
            dirs.cut()
            try:
                server = crash.ServerProcess(dirs.store, log_path, env=dirs.env())
                opened += 1
            except RuntimeError as err:  # kept for a look; the next iteration starts a new group
                failed += 1
                server = None
                kept = shutil.move(dirs.scratch, tempfile.mkdtemp(prefix="graspsim-power-cut-failed-"))
                dirs = None
                log(f"power cut {iteration + 1}: the server did not start on what the cut left (kept: {kept}): {err}")
                continue
            crash.check(server.client, scenes, grasp_sets, counts)
            log(f"power cut {iteration + 1}/{iterations}: after {delay:.2f} s, restart {server.start_s:.2f} s,"
                f" {server.scenes_restored} scenes; lost {counts['acknowledged_lost']},"
                f" partial {counts['partial_visible']}, unacknowledged seen {counts['unacknowledged_seen']},"
                f" grasp sets lost {counts['grasp_sets_lost']}")
        crash.stop_last(server)
    finally:
        crash.kill_left(server)
        shutil.rmtree(scratch, ignore_errors=True)
    return {"power_cut_iterations": iterations, "power_cut_seed": seed, "power_cut_rule": rule,
            "power_cut_acknowledged_lost": counts["acknowledged_lost"],
            "power_cut_partial_visible": counts["partial_visible"],
            "power_cut_unacknowledged_seen": counts["unacknowledged_seen"],
            "power_cut_store_opened": opened, "power_cut_store_failed": failed,
            "power_cut_scenes_checked": counts["scenes_checked"],
            "power_cut_acknowledged_writes": sum(v for k, v in writes.items() if k != "grasp_set"),
            "power_cut_grasp_sets_acknowledged": writes.get("grasp_set", 0),
            "power_cut_grasp_sets_lost": counts["grasp_sets_lost"]}
