"""physics "work_cycle_*" figures: the tactile work cycle (the PG70 on its z axis grasps, lifts 5 cm, holds 1 s,
sets down and releases the 5 cm cube) on each of the server's three engines, same scene, same server, same gRPC
stream, in the same run, each with its defaults (1 ms, one sub-step), which do the task (MuJoCo's default
contact softness holds the cube; Bullet's drive is implicit, a soft velocity row). steps/s counts 1 ms steps (the cycle's simulated time / 1 ms) over the
client's wall time of RunWorkCycle, REPEATS runs each, median (min-max). "held": the cube stayed within 3 mm of
its lifted height through the hold, in every run. The pads read through each engine's contacts
(physics/pad_readout.h on MuJoCo and Bullet)."""
import statistics
import time

from _harness import log

REPEATS = 5
ENGINES = ("graspsim", "mujoco", "bullet")
TABLE_TOP, CUBE, LIFT = 0.75, 0.05, 0.05


def _one_cycle(client, engine):
    scene = client.create_scene(f"bench_cycle_{engine}")
    try:
        client.add_object(scene.id, "table", builtin="table")
        client.add_object(scene.id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
        client.add_robot(scene.id, "cell", builtin="schunk_pg70_on_z_axis", base_pose=[0, 0, 1.05, 1, 0, 0, 0])
        params = client.set_simulation_params(scene.id, engine=engine)
        t0 = time.perf_counter()
        result = client.run_work_cycle(scene.id, "cell", "cube", lift_height=LIFT, timeout=600, progress=False)
        wall = time.perf_counter() - t0
    finally:
        client.delete_scene(scene.id)
    hold = [i for i, stage in enumerate(result.stage) if stage == "hold"]
    held = bool(hold) and all(abs(result.object_position[i, 2] - (TABLE_TOP + CUBE / 2 + LIFT)) < 3e-3 for i in hold)
    return result.time[-1] / params.time_step / wall, held


def work_cycle_figures(client) -> dict:
    per_s, held = {}, {}
    for engine in ENGINES:
        runs = [_one_cycle(client, engine) for _ in range(REPEATS)]
        rates = [rate for rate, _ in runs]
        per_s[engine] = {"median": round(statistics.median(rates)), "min": round(min(rates)),
                         "max": round(max(rates))}
        held[engine] = all(ok for _, ok in runs)
        log(f"work cycle on {engine}: {per_s[engine]} steps/s, held {held[engine]}")
    return {"work_cycle_steps_per_s": per_s, "work_cycle_held": held,
            "work_cycle_graspsim_over_mujoco": round(per_s["graspsim"]["median"] / per_s["mujoco"]["median"], 3),
            "work_cycle_graspsim_over_bullet": round(per_s["graspsim"]["median"] / per_s["bullet"]["median"], 3)}
