"""physics "work_cycle_*" figures: the tactile work cycle (the PG70 on its z axis grasps, lifts 5 cm, holds 1 s,
sets down and releases the 5 cm cube) on each of the server's three engines, same scene, same server, same gRPC
stream, in the same run, each with its defaults (1 ms, one sub-step), which do the task (MuJoCo's default
contact softness holds the cube; Bullet's drive is implicit, a soft velocity row). steps/s counts 1 ms steps (the cycle's simulated time / 1 ms) over the
client's wall time of RunWorkCycle, REPEATS runs each, median (min-max). "held": the cube stayed within 3 mm of
its lifted height through the hold, in every run. The pads read through each engine's contacts
(physics/pad_readout.h on MuJoCo and Bullet).

"grasp_*" figures: physics.py's steps_per_s scene (the PG70 pointing down, closed on the cube on the table by its
drive at 1 A) built on each engine, then REPEATS timed StepSimulation(steps=2000) calls, median (min-max) of
their steps/s; then the table is removed and the cube must stay within 1 mm over 2000 more steps ("held"; z before
minus z after, µm: "grasp_drift_um_by_engine").
"""
import statistics
import time

from _harness import log
from tactile import CUBE_EDGE, TABLE_TOP_Z, cycle

REPEATS = 5
TIMED_STEPS = 2000
FINGER = "pg70/finger_left_joint"
CURRENT_LIMIT_A = 1.0     # PG70 drive: 200 N at 3.5 A, so ≈ 57 N per finger
CLOSE_SPEED = 0.02        # m/s, closing (the joint's 0 is closed)
DEFAULTS = dict(time_step=1e-3, integrator="linearly_implicit_euler")
ENGINES = ("graspsim", "mujoco", "bullet")
LIFT, STEP = 0.05, 1e-3


def _one_cycle(client, engine):
    """The tactile bench's cycle (tests/bench/tactile.py) on `engine`: steps/s and whether the cube was held."""
    result, wall = cycle(client, hold_time=1.0, time_step=STEP, engine=engine, lift_height=LIFT, progress=False)
    hold = [i for i, stage in enumerate(result.stage) if stage == "hold"]
    lifted = TABLE_TOP_Z + CUBE_EDGE / 2 + LIFT
    held = bool(hold) and all(abs(result.object_position[i, 2] - lifted) < 3e-3 for i in hold)
    return result.time[-1] / STEP / wall, held


def _spread(rates) -> dict:
    return {"median": round(statistics.median(rates)), "min": round(min(rates)), "max": round(max(rates))}


def work_cycle_figures(client) -> dict:
    per_s, held = {}, {}
    for engine in ENGINES:
        runs = [_one_cycle(client, engine) for _ in range(REPEATS)]
        per_s[engine] = _spread([rate for rate, _ in runs])
        held[engine] = all(ok for _, ok in runs)
        log(f"work cycle on {engine}: {per_s[engine]} steps/s, held {held[engine]}")
    return {"work_cycle_steps_per_s": per_s, "work_cycle_held": held,
            "work_cycle_graspsim_over_mujoco": round(per_s["graspsim"]["median"] / per_s["mujoco"]["median"], 3),
            "work_cycle_graspsim_over_bullet": round(per_s["graspsim"]["median"] / per_s["bullet"]["median"], 3)}


def pg70_closed_on_cube(client, engine: str) -> str:
    """A new scene: the PG70 pointing down (approach axis −z), fingertips 1 cm above the table, closed by its
    drive on the 5 cm cube. Returns the scene id."""
    scene_id = client.create_scene(f"physics_{engine}").id
    # Rotated half a turn about x; the fingers span the cube's lower 4 cm and the housing clears its top by 2 cm.
    client.add_robot(scene_id, "pg70", builtin="schunk_pg70", base_pose=[0, 0, TABLE_TOP_Z + 0.01 + 0.157, 0, 1, 0, 0])
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP_Z + CUBE_EDGE / 2, 1, 0, 0, 0])
    client.set_simulation_params(scene_id, engine=engine, **DEFAULTS)
    client.set_joint_positions(scene_id, {FINGER: 0.03})  # open: 6 cm between the fingers
    client.step_simulation(scene_id, steps=300)           # the cube settles on the table
    client.set_actuator(scene_id, FINGER, "velocity", -CLOSE_SPEED, current_limit=CURRENT_LIMIT_A)
    client.step_simulation(scene_id, steps=1000)          # 10 mm to close at 20 mm/s, then settle
    return scene_id


def grasp_engine_figures(client) -> dict:
    per_s, held, drift = {}, {}, {}
    for engine in ENGINES:
        scene_id = pg70_closed_on_cube(client, engine)
        rates = []
        for _ in range(REPEATS):
            t0 = time.perf_counter()
            client.step_simulation(scene_id, steps=TIMED_STEPS)
            rates.append(TIMED_STEPS / (time.perf_counter() - t0))
        client.remove_body(scene_id, "table")
        client.step_simulation(scene_id, steps=200)  # the grip takes the weight
        z1 = client.get_body_poses(scene_id, ["cube"])["cube"].position[2]
        client.step_simulation(scene_id, steps=TIMED_STEPS)
        z2 = client.get_body_poses(scene_id, ["cube"])["cube"].position[2]
        client.delete_scene(scene_id)
        per_s[engine] = _spread(rates)
        held[engine] = bool(abs(z2 - z1) < 1e-3)
        drift[engine] = round((z1 - z2) * 1e6, 1)
        log(f"PG70 on the cube on {engine}: {per_s[engine]} steps/s, held {held[engine]} ({(z1 - z2) * 1e6:.1f} µm)")
    return {"grasp_steps_per_s_by_engine": per_s, "grasp_held_by_engine": held, "grasp_drift_um_by_engine": drift,
            "grasp_graspsim_over_mujoco": round(per_s["graspsim"]["median"] / per_s["mujoco"]["median"], 3),
            "grasp_graspsim_over_bullet": round(per_s["graspsim"]["median"] / per_s["bullet"]["median"], 3)}
