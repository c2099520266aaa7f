"""The power-cut injector (tests/stress/power_cut_shim.c, docs/durability.md) really drops what was not made
durable: small programs write under it, and the directory rebuilt by power_cut.cut() must hold exactly what POSIX
promises after a power cut — no more (else the power-cut benchmark would pass vacuously), no less. Then the server
itself: a data directory it creates survives, and a short seeded run of the power-cut benchmark loses nothing."""
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
import crash  # noqa: E402  (tests/bench/crash.py)
import power_cut  # noqa: E402  (tests/bench/power_cut.py)

# What the programs below share: d is the directory watched.
PRELUDE = """
import os, sys
d = sys.argv[1]
def put(name, data, sync=False, flags=os.O_CREAT | os.O_TRUNC):
    fd = os.open(os.path.join(d, name), os.O_WRONLY | flags, 0o644)
    os.write(fd, data)
    if sync:
        os.fsync(fd)
    os.close(fd)
def sync_dir():
    fd = os.open(d, os.O_RDONLY)
    os.fsync(fd)
    os.close(fd)
"""


@pytest.fixture(autouse=True)
def shim_built():
    if not power_cut.SHIM.is_file():
        pytest.fail(f"{power_cut.SHIM} not found: build it (make)", pytrace=False)


def contents(directory: Path) -> dict:
    return {p.name: p.read_bytes() for p in directory.iterdir() if p.is_file()}


def cut_after(tmp_path: Path, program: str, rule: str = "posix", before: dict = None):
    """Runs program under the shim on a directory holding `before` (durable: it is there at start); returns the
    directory as the process left it and as a power cut right after it would."""
    live, state, out = tmp_path / "live", tmp_path / "state", tmp_path / "cut"
    live.mkdir()
    state.mkdir()
    for name, data in (before or {}).items():
        (live / name).write_bytes(data)
    subprocess.run([sys.executable, "-c", PRELUDE + program, str(live)], env=power_cut.shim_env(live, state, rule),
                   check=True, timeout=60)
    power_cut.cut(live, state, out)
    return live, out


def test_what_was_not_synced_is_dropped(tmp_path):
    live, cut = cut_after(tmp_path, """
put("named", b"synced", sync=True)
put("empty", b"never synced")       # its name made durable below, its content never
sync_dir()
put("named", b"-more", flags=os.O_APPEND)
put("nameless", b"synced", sync=True)  # content synced, its name never
""")
    assert contents(live) == {"named": b"synced-more", "empty": b"never synced", "nameless": b"synced"}
    assert contents(cut) == {"named": b"synced", "empty": b""}


@pytest.mark.parametrize("dir_synced", [False, True])
def test_rename_and_unlink_wait_for_the_directory_fsync(tmp_path, dir_synced):
    live, cut = cut_after(tmp_path, f"""
put("config.tmp", b"new", sync=True)
os.rename(os.path.join(d, "config.tmp"), os.path.join(d, "config"))
os.unlink(os.path.join(d, "gone"))
put("kept", b"overwritten, never synced")
if {dir_synced}:
    sync_dir()
""", before={"config": b"old", "gone": b"x", "kept": b"kept"})
    assert contents(live) == {"config": b"new", "kept": b"overwritten, never synced"}
    if dir_synced:
        assert contents(cut) == {"config": b"new", "kept": b"kept"}
    else:
        assert contents(cut) == {"config": b"old", "gone": b"x", "kept": b"kept"}


@pytest.mark.parametrize("rule", ["posix", "journal"])
def test_the_journal_rule_makes_names_durable_at_any_fsync(tmp_path, rule):
    _, cut = cut_after(tmp_path, 'put("file", b"synced", sync=True)', rule=rule)
    assert contents(cut) == ({"file": b"synced"} if rule == "journal" else {})


@pytest.mark.parametrize("synchronous", ["FULL", "NORMAL"])
def test_sqlite_commits_survive_with_full_only(tmp_path, synchronous):
    """SQLite as the server uses it (WAL): with synchronous=FULL every commit survives the cut; with NORMAL the
    commits since the last checkpoint are lost, as SQLite documents for a power cut."""
    _, cut = cut_after(tmp_path, f"""
import sqlite3
db = sqlite3.connect(os.path.join(d, "t.sqlite"), isolation_level=None)
db.execute("PRAGMA journal_mode=WAL")
db.execute("PRAGMA synchronous={synchronous}")
db.execute("CREATE TABLE t (x INTEGER)")
for x in range(50):
    db.execute("INSERT INTO t VALUES (?)", (x,))
os._exit(0)  # no close: the process dies, as under SIGKILL
""")
    db = sqlite3.connect(cut / "t.sqlite")
    try:
        rows = db.execute("SELECT count(*) FROM t").fetchone()[0]
    except sqlite3.OperationalError:  # no such table: not even the CREATE TABLE survived
        rows = 0
    db.close()
    assert rows == (50 if synchronous == "FULL" else 0)


def test_a_data_directory_the_server_creates_survives(tmp_path):
    """The store syncs the directories it creates (server/src/core/sqlite_file.cpp): without that, everything
    acknowledged on a first start was lost by a power cut under the strict rule."""
    live, state = tmp_path / "live", tmp_path / "state"
    live.mkdir()
    state.mkdir()
    server = crash.ServerProcess(str(live / "a" / "store"), tmp_path / "server.log",
                                 env=power_cut.shim_env(live, state))
    scene = server.client.create_scene("kept").id
    server.client.add_object(scene, "box", box=[0.1, 0.1, 0.1], mass=1.0)
    server.kill()
    power_cut.cut(live, state, tmp_path / "cut")
    server = crash.ServerProcess(str(tmp_path / "cut" / "a" / "store"), tmp_path / "server.log")
    try:
        assert [s.name for s in server.client.list_scenes()] == ["kept"]
        assert "box" in {b.id for b in server.client.get_scene(scene).bodies}
    finally:
        assert server.stop() == 0


def test_power_cut_short():
    """3 seeded power cuts of the crash benchmark's workload: nothing acknowledged lost, the store opens."""
    figures = power_cut.power_cut_iterations(3, seed=5, group=3)
    assert figures["power_cut_acknowledged_lost"] == 0, figures
    assert figures["power_cut_partial_visible"] == 0, figures
    assert figures["power_cut_store_opened"] == 3, figures
    assert figures["power_cut_grasp_sets_lost"] == 0, figures
    assert figures["power_cut_acknowledged_writes"] > 0 and figures["power_cut_scenes_checked"] >= 3, figures


def test_a_disk_ignoring_flushes_loses_acknowledged_writes():
    """The same check is not vacuous: when fsync makes nothing durable, acknowledged writes are lost."""
    figures = power_cut.power_cut_iterations(1, seed=5, group=1, rule="nosync")
    assert figures["power_cut_acknowledged_lost"] > 0, figures


def test_a_stopped_recording_survives(tmp_path):
    """A recording acknowledged as stopped is on the disk (recording/mcap_writer.cpp and ros2_bag.cpp sync the file,
    the bag's metadata and their directory entries): after a power cut right after StopRecording, the MCAP file
    reads to its summary and the ROS 2 bag's metadata names its messages. Without the syncs both come back empty."""
    from mcap.reader import make_reader
    live, state = tmp_path / "live", tmp_path / "state"
    live.mkdir()
    state.mkdir()
    server = crash.ServerProcess(str(live / "store"), tmp_path / "server.log", env=power_cut.shim_env(live, state))
    client = server.client
    scene = client.create_scene("recorded").id
    client.add_object(scene, "cube", builtin="cube_5cm", pose=[0, 0, 0.1, 1, 0, 0, 0])
    client.start_recording(scene, name="kept.mcap", groups=["graspsim", "ros2"])
    client.step_simulation(scene, 0.2)
    stopped = client.stop_recording(scene)
    assert stopped.messages > 0
    server.kill()
    power_cut.cut(live, state, tmp_path / "cut")
    recordings = tmp_path / "cut" / "store" / "recordings"
    with open(recordings / "kept.mcap", "rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and sum(summary.statistics.channel_message_counts.values()) == stopped.messages
    metadata = (recordings / "kept.ros2" / "metadata.yaml").read_text()
    assert "message_count:" in metadata and "message_count: 0\n  topics" not in metadata
    with open(recordings / "kept.ros2" / "kept.ros2_0.mcap", "rb") as f:
        assert make_reader(f).get_summary() is not None
