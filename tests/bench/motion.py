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
"""
import json
import subprocess

from _harness import REPO, log

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
    return figures, 0
