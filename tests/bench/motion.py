"""motion: arm path planning speed and success (issue 7), in process (graspsim_motion_bench).

100 seeded table-top problems, alternately the KUKA KR 5 sixx R850 with the Barrett hand and the PA10 with the
PG70, on the 1.2 x 0.8 m table among 3-8 random boxes, cylinders and balls (5-30 cm tall) and a random box object:
from the hand over one spot (fingertips 15-30 cm above the table) to the pre-grasp over the object (fingertips 5
cm above its top, palm down, random yaw). A problem is kept when the exact geometry finds a collision-free IK
solution of the goal pose, and both the exact geometry and the sphere model one of the start pose (the start
stands for where the last plan left the arm); draws that fail are replaced ("rejected_draws").

- plan_ms_p50 / _p95 / _max, success_rate: motion::PlanPathToPose, wall time of the whole plan: IK of the goal
  pose, checks of start and goals, the straight segment or RRT-Connect, shortcutting, time parameterisation;
  plan_cpu_ms_*: the same as thread CPU time (honest under load); setup_ms_p50: sphere model and obstacles.
- ompl_default_ms_p50 / _p95, ompl_default_success_rate: plain OMPL RRT-Connect on the same start and the same
  free goal configurations: default range, OMPL's DiscreteMotionValidator at its default resolution, validity by
  the exact geometry (ContactFinder, 5 mm samples); solve() only; unsolved runs count with their timeout.
- speedup_p50 = ompl_default_ms_p50 / plan_ms_p50.
- rrt_forced_ms_p50 / _p95, rrt_forced_failures: the same plans with the straight-segment try switched off, so
  that RRT-Connect searches every problem (in these problems the straight joint-space segment is usually free).
- pick_place_success_rate, pick_place_ms_p50 / _max, pick_place_sim_s_p50: GraspService.PickAndPlace through a
  real server on PICK_PROBLEMS seeded problems (alternately the KR 5 and the PA10 with the PG70; the 5 cm cube at a
  random spot and yaw on the table, the goal at another, both within reach): success as the cube's pose read back
  from the scene within 1 cm and 10° of the goal; wall time of the whole call (grasp set planned each time, the
  table differs in the object's frame), simulated seconds.
"""
import json
import math
import subprocess
import time

import numpy as np

from _harness import REPO, Server, log, ms_stats

BIN = REPO / "build" / "bin" / "graspsim_motion_bench"
PROBLEMS, BASELINE_TIMEOUT_S = 100, 10


def run():
    if not BIN.exists():
        raise RuntimeError(f"{BIN} not found: build it (ninja -C build graspsim_motion_bench)")
    log(f"{BIN.name}: {PROBLEMS} problems, plain OMPL timeout {BASELINE_TIMEOUT_S} s")
    done = subprocess.run([str(BIN), str(PROBLEMS), str(BASELINE_TIMEOUT_S)], capture_output=True, text=True,
                          check=True)
    figures = json.loads(done.stdout.strip().splitlines()[-1])
    for line in done.stderr.strip().splitlines()[-3:]:
        log(line)
    figures.update(pick_and_place())
    return figures, 0


PICK_PROBLEMS, TABLE = 6, 0.75


def _spot(rng, side):
    """A cube pose on the table in front of the arm (base at x = -0.45), on one side of it, random yaw."""
    x, y, yaw = rng.uniform(-0.05, 0.2), side * rng.uniform(0.12, 0.3), rng.uniform(-math.pi, math.pi)
    return [x, y, TABLE + 0.025, math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)]


def pick_and_place():
    import graspsim  # the client package (build/venv)
    rng = np.random.default_rng(7)
    seconds, simulated, ok = [], [], 0
    with Server() as server, graspsim.connect(server.address) as client:
        for k in range(PICK_PROBLEMS):
            arm = ("kuka_kr5_sixx_r850_pg70", "mitsubishi_pa10_pg70")[k % 2]
            side = 1 if k % 4 < 2 else -1
            start, goal = _spot(rng, side), _spot(rng, -side)
            scene = client.create_scene(f"pick {k}").id
            client.add_object(scene, "table", builtin="table")
            client.add_object(scene, "cube", builtin="cube_5cm", pose=start)
            client.add_robot(scene, "arm", builtin=arm, base_pose=[-0.45, 0, TABLE, 1, 0, 0, 0])
            t = time.perf_counter()
            try:
                result = client.pick_and_place(scene, "arm", "cube", goal, seed=k + 1)
                simulated.append(result.simulated_seconds)
            except graspsim.GraspsimError as err:
                log(f"problem {k} ({arm}): {err.message[:300]}")
            seconds.append(time.perf_counter() - t)
            end = client.get_body_poses(scene, ["cube"])["cube"]
            error = float(np.linalg.norm(np.asarray(end.position) - goal[:3]))
            angle = 2 * math.acos(min(1.0, abs(float(np.dot(end.orientation, goal[3:])))))
            ok += error < 0.01 and angle < math.radians(10)
            client.delete_scene(scene)
    log(f"pick and place: {ok} of {PICK_PROBLEMS} placed")
    out = {"pick_place_problems": PICK_PROBLEMS, "pick_place_success_rate": ok / PICK_PROBLEMS}
    stats = ms_stats("pick_place", seconds)
    out.update({key: stats[key] for key in stats if key.endswith(("_p50", "_max"))})
    out["pick_place_sim_s_p50"] = float(np.median(simulated)) if simulated else 0.0
    return out
