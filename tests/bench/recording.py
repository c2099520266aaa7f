"""record: what recording a scene costs (issue 25): the grasp work cycle's simulation speed without and with a
recording of all three channel groups (graspsim, foxglove, ros2), the file size, and the frames the writer dropped.

Workload: the built-in "schunk_pg70_on_z_axis" over the table and the 5 cm cube (as tests/bench/tactile.py and
clients/python/examples/tactile_cycle.py build it), full coverage, a HOLD_S hold (HOLD_S + 3.35 s simulated),
the F/T reading of the finger joint recorded too. HOLD_S = 42 s makes the paper's 45 s cycle (45.35 s simulated),
long enough in wall time that the start and the finish of a recording are not all it measures. Each run has a
fresh scene on one server of our own (--recording-dir in a temporary directory, --foxglove-listen=off: no live
viewer costs anything).

- steps_per_s_without / _with: simulation steps (simulated time / time step) per wall second of the whole
  RunWorkCycle call, with: from StartRecording's answer to StopRecording's (the file finished: summary, index,
  the ROS 2 bag closed), so a writer that lags and catches up at the stop is charged. REPS of each, interleaved
  (without/with, then with/without, ...) so that drift in the machine's load hits both alike, after one warm-up
  of each; medians, with [min, max] as the spread.
- record_overhead_pct: (1 - steps_per_s_with / steps_per_s_without) * 100 of the two medians (goal <= 5);
  record_overhead_pct_paired: the median (and spread) of the same ratio per adjacent pair.
- mb_per_sim_minute: MB (10^6 bytes) of the .mcap plus its ROS 2 bag directory per simulated minute, median over
  the recorded runs; mcap_mb_per_sim_minute: the .mcap alone.
- dropped_messages: the recordings' dropped_frames added up (states the server's writer could not keep up with);
  frames_per_run, messages_per_run: medians of the recordings' frames and MCAP messages.
Wall-clock figures depend on the machine's load: load_avg_start / load_avg_end (1 min load average) are reported.

Environment: GRASPSIM_RECORD_REPS (5), GRASPSIM_RECORD_HOLD_S (42).
"""
import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

import graspsim

from _harness import Server, log

REPS = int(os.environ.get("GRASPSIM_RECORD_REPS", "5"))
HOLD_S = float(os.environ.get("GRASPSIM_RECORD_HOLD_S", "42"))
TABLE_TOP_Z, CUBE_EDGE, GRIPPER_BASE_Z = 0.75, 0.05, 1.05  # as tests/bench/tactile.py
GRIPPER, CUBE = "cell", "cube"
FT_JOINT = "cell/finger_left_joint"
OVERHEAD_GOAL_PCT = 5.0


def _size(path: str) -> int:
    """Bytes of a file, or of every file under a directory ("" or missing: 0)."""
    if not path or not os.path.exists(path):
        return 0
    if os.path.isfile(path):
        return os.path.getsize(path)
    return sum(p.stat().st_size for p in Path(path).rglob("*") if p.is_file())


def _cycle(client, recorded: bool, run: int) -> dict:
    """One work cycle on a fresh scene; with `recorded`, between StartRecording and StopRecording."""
    scene_id = client.create_scene(f"record bench {run}").id
    info = None
    try:
        client.add_object(scene_id, "table", builtin="table")
        client.add_object(scene_id, CUBE, builtin="cube_5cm", pose=[0, 0, TABLE_TOP_Z + CUBE_EDGE / 2, 1, 0, 0, 0])
        client.add_robot(scene_id, GRIPPER, builtin="schunk_pg70_on_z_axis",
                         base_pose=[0, 0, GRIPPER_BASE_Z, 1, 0, 0, 0])
        time_step = client.get_simulation_params(scene_id).time_step
        if recorded:
            client.start_recording(scene_id, name=f"run-{run}.mcap", force_torque_joints=[FT_JOINT])
        started = time.perf_counter()
        result = client.run_work_cycle(scene_id, GRIPPER, CUBE, hold_time=HOLD_S, timeout=900)
        if recorded:
            info = client.stop_recording(scene_id)
        wall = time.perf_counter() - started
    finally:
        client.delete_scene(scene_id)
    simulated = float(result.time[-1])  # a fresh scene starts at t = 0
    row = {"steps_per_s": round(simulated / time_step) / wall, "simulated_s": simulated, "wall_s": wall}
    if info is not None:
        mcap_bytes, ros2_bytes = _size(info.path), _size(info.ros2_path)
        row.update(mcap_bytes=mcap_bytes, ros2_bytes=ros2_bytes, frames=info.frames, messages=info.messages,
                   dropped=info.dropped_frames, recorded_s=info.end_time - info.start_time)
        os.unlink(info.path)  # keep the disk free for the next runs
        if info.ros2_path:
            shutil.rmtree(info.ros2_path, ignore_errors=True)
    return row


def _median_spread(values, digits=1):
    values = np.asarray(values, dtype=np.float64)
    return round(float(np.median(values)), digits), [round(float(values.min()), digits),
                                                     round(float(values.max()), digits)]


def run():
    load_start = round(os.getloadavg()[0], 2)
    recordings = tempfile.mkdtemp(prefix="graspsim-bench-recordings-")
    without, with_ = [], []
    try:
        with Server(f"--recording-dir={recordings}", "--foxglove-listen=off") as server, \
                graspsim.connect(server.address) as client:
            log(f"record: warm-up (one cycle each, hold {HOLD_S:g} s)")
            _cycle(client, False, -1)
            _cycle(client, True, -2)
            for rep in range(REPS):
                order = (False, True) if rep % 2 == 0 else (True, False)
                for recorded in order:
                    row = _cycle(client, recorded, rep)
                    (with_ if recorded else without).append(row)
                    log(f"rep {rep + 1}/{REPS} {'with' if recorded else 'without'} recording: "
                        f"{row['steps_per_s']:.0f} steps/s ({row['simulated_s']:.2f} s simulated in "
                        f"{row['wall_s']:.2f} s)" + (f", {row['frames']} frames, "
                                                      f"{(row['mcap_bytes'] + row['ros2_bytes']) / 1e6:.2f} MB, "
                                                      f"{row['dropped']} dropped" if recorded else ""))
    finally:
        shutil.rmtree(recordings, ignore_errors=True)
    rate_without = [r["steps_per_s"] for r in without]
    rate_with = [r["steps_per_s"] for r in with_]
    median_without, spread_without = _median_spread(rate_without)
    median_with, spread_with = _median_spread(rate_with)
    overhead = (1 - float(np.median(rate_with)) / float(np.median(rate_without))) * 100
    paired = [(1 - w / wo) * 100 for w, wo in zip(rate_with, rate_without)]
    paired_median, paired_spread = _median_spread(paired, 2)
    minutes = [r["simulated_s"] / 60 for r in with_]
    total_mb = [(r["mcap_bytes"] + r["ros2_bytes"]) / 1e6 / m for r, m in zip(with_, minutes)]
    mcap_mb = [r["mcap_bytes"] / 1e6 / m for r, m in zip(with_, minutes)]
    figures = {
        "record_overhead_pct": round(overhead, 2),
        "record_overhead_goal_pct": OVERHEAD_GOAL_PCT,
        "record_overhead_goal_met": overhead <= OVERHEAD_GOAL_PCT,
        "record_overhead_pct_paired": paired_median, "record_overhead_pct_paired_spread": paired_spread,
        "steps_per_s_without": median_without, "steps_per_s_without_spread": spread_without,
        "steps_per_s_with": median_with, "steps_per_s_with_spread": spread_with,
        "mb_per_sim_minute": round(float(np.median(total_mb)), 3),
        "mb_per_sim_minute_spread": [round(min(total_mb), 3), round(max(total_mb), 3)],
        "mcap_mb_per_sim_minute": round(float(np.median(mcap_mb)), 3),
        "dropped_messages": int(sum(r["dropped"] for r in with_)),
        "frames_per_run": int(np.median([r["frames"] for r in with_])),
        "messages_per_run": int(np.median([r["messages"] for r in with_])),
        "cycle_simulated_s": round(float(np.median([r["simulated_s"] for r in without + with_])), 3),
        "reps": REPS, "hold_s": HOLD_S,
        "load_avg_start": load_start, "load_avg_end": round(os.getloadavg()[0], 2),
    }
    figures["load_avg_1m"] = [figures["load_avg_start"], figures["load_avg_end"]]
    return figures, server.exit_code
