"""physics: simulation speed of a PG70 holding a cube, through the server; accuracy and stability in process.

- steps_per_s: StepSimulation(steps=2000) through the Python client on one scene: the built-in PG70 pointing
  down over the table, its fingers closed on the 5 cm cube with the PG70 drive (velocity mode, 1 A current
  limit ≈ 57 N per finger), default parameters (1 ms, linearly implicit Euler). Then the table is removed and the
  cube hangs in the grip alone for another 2000 steps (sleeping off, so the cube is integrated every step): the
  "holding" check (cube z within 1 mm) — the gripper's base is welded to the world, so this stands for a lift.
- settle_rel_error, stribeck_max_rel_error, runtime_vs_error: graspsim_physics_bench (tests/stress/accuracy.h),
  the analytic tests of simulation_test.cpp at 5 time steps × 3 integrators.
- stable_fraction: graspsim_stress --reduced (360 runs of the stability sweep, docs/physics-stability.md).
- textbook_*, mujoco_within_1pct, bullet_within_1pct, energy_drift_pct_max, textbook (per case, engine and dt):
  the closed-form cases of tests/physics/textbook.py on the server's three engines (tests/bench/physics_textbook.py),
  with the error-against-run-time plot docs/physics-textbook.png.
- work_cycle_steps_per_s, work_cycle_held, work_cycle_graspsim_over_mujoco / _over_bullet: the tactile work cycle
  on each of the server's three engines, same run; grasp_steps_per_s_by_engine, grasp_held_by_engine,
  grasp_graspsim_over_mujoco / _over_bullet: the steps_per_s scene on each engine (tests/bench/physics_engines.py).
Wall-clock figures (steps_per_s, the textbook run times) move with the machine's other load: bench.py adds
load_avg_1m (start, end); the errors are deterministic and do not.
"""
import json
import subprocess
import time

import graspsim

from _harness import REPO, Server, log
from physics_engines import DEFAULTS, FINGER, grasp_engine_figures, pg70_closed_on_cube, work_cycle_figures
from physics_textbook import textbook_figures

BIN = REPO / "build" / "bin"
TIMED_STEPS = 2000


def timed_steps(client, scene_id: str):
    t0 = time.perf_counter()
    response = client.step_simulation(scene_id, steps=TIMED_STEPS)
    return TIMED_STEPS / (time.perf_counter() - t0), response


def grasp(client) -> dict:
    scene_id = pg70_closed_on_cube(client, "graspsim")
    finger = client.get_joint_positions(scene_id, [FINGER])[FINGER]
    z0 = client.get_body_poses(scene_id, ["cube"])["cube"].position[2]
    log(f"grasped: finger at {finger * 1e3:.3f} mm (pad foam meets the cube at 24 mm), cube z {z0:.6f} m")
    per_s, response = timed_steps(client, scene_id)
    figures = {"steps_per_s": round(per_s), "timed_steps": TIMED_STEPS, "contacts": response.contacts,
               "finger_mm": round(finger * 1e3, 3)}

    client.remove_body(scene_id, "table")
    client.set_simulation_params(scene_id, **DEFAULTS, sleep_time=0.0)
    client.step_simulation(scene_id, steps=200)           # the grip takes the weight
    z1 = client.get_body_poses(scene_id, ["cube"])["cube"].position[2]
    per_s, response = timed_steps(client, scene_id)
    z2 = client.get_body_poses(scene_id, ["cube"])["cube"].position[2]
    figures.update({"held_steps_per_s": round(per_s), "held_contacts": response.contacts,
                    "held_awake_bodies": response.awake_bodies,
                    "held_drop_um": round((z0 - z1) * 1e6, 3), "held_drift_um": round((z1 - z2) * 1e6, 3),
                    "holding": abs(z2 - z1) < 1e-3 and response.contacts > 0})
    log(f"held without the table: drop {figures['held_drop_um']} µm, then {figures['held_drift_um']} µm over "
        f"{TIMED_STEPS} steps, {response.contacts} contacts")
    return figures


def accuracy() -> dict:
    log("graspsim_physics_bench: settle and Stribeck tests, 5 time steps x 3 integrators")
    data = json.loads(subprocess.run([str(BIN / "graspsim_physics_bench")], capture_output=True, text=True,
                                     check=True).stdout)
    table = []
    for test in ("settle", "stribeck"):
        for row in data[test]:
            entry = {"test": test, "integrator": row["integrator"], "dt": row["dt"],
                     "error": float(f"{row['rel_error']:.3g}"), "run_s": round(row["seconds"], 4)}
            if test == "settle":
                entry["peak_error"] = float(f"{row['peak_rel_error']:.3g}")
            else:
                entry["worst_speed"] = row["worst_speed"]
            if row["error"]:
                entry["failed"] = row["error"]
            table.append(entry)

    def at(test, integrator, dt=1e-3):
        return next(r for r in table if r["test"] == test and r["integrator"] == integrator and r["dt"] == dt)

    default = "linearly_implicit_euler"
    return {"settle_rel_error": at("settle", default)["error"],
            "settle_peak_rel_error": at("settle", default)["peak_error"],
            "stribeck_max_rel_error": at("stribeck", default)["error"],
            "stribeck_max_rel_error_semi_implicit": at("stribeck", "semi_implicit_euler")["error"],
            "runtime_vs_error": table}


def stability() -> dict:
    log("graspsim_stress --reduced: 360 runs")
    lines = subprocess.run([str(BIN / "graspsim_stress"), "--reduced"], capture_output=True, text=True,
                           check=True).stdout.splitlines()
    summary = json.loads(lines[-1])
    return {"stable_fraction": round(summary["stable_fraction"], 3), "stable_sweep": "reduced",
            "stable_runs": summary["stable"], "sweep_runs": summary["runs"], "sweep_diverged": summary["diverged"],
            "sweep_insane": summary["insane"], "sweep_contract_breaches": summary["contract_breaches"]}


def run():
    for binary in ("graspsim_physics_bench", "graspsim_stress"):
        if not (BIN / binary).exists():
            raise RuntimeError(f"{BIN / binary} not built: run 'make build'")
    with Server() as server, graspsim.connect(server.address) as client:
        figures = grasp(client)
        figures.update(textbook_figures(client))
        figures.update(work_cycle_figures(client))
        figures.update(grasp_engine_figures(client))
    figures.update(accuracy())
    figures.update(stability())
    return figures, server.exit_code
