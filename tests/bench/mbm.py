"""mbm: the MotionBenchMaker Panda problems (issue 20) through GraspService.PlanArmPath, with OMPL as the peer and
an independent re-check of the planned paths in PyBullet.

Problems: tests/data/mbm.py (vamp-planner 0.6.4's sdist from PyPI, fetched into build/bench-data on first use):
7 scenes (bookshelf_small, bookshelf_tall, bookshelf_thin, box, cage, table_pick, table_under_pick) x 100, each a
start and a goal configuration of the Panda's 7 arm joints among boxes and cylinders. One server; per problem a
scene of its own: the robot from VAMP's panda_spherized.urdf (add_robot(path=...), base at the world origin; that
file's finger joints are fixed, open at 6.5 cm as in the problems' start states) and every obstacle as a static
body; deleted after the problem.

- plan_us_*, solved_rate: graspsim's planner (planner="", vectorised RRT-Connect), REPS runs per problem (seeds
  1..REPS, timeout TIMEOUT_S each); a problem's time is the median over its runs of ArmPath.seconds (server-side
  planning time); an unsolved or refused run counts as TIMEOUT_S (its first message per problem in "failures").
  Once more than half of a problem's runs are unsolved its median is TIMEOUT_S whatever the others do, so they
  are skipped (runs_skipped): unsolvable problems cost 3 timeouts, not 5. p5/p50/p95/max over problems;
  plan_us_p50_rep_range: [min, max] over the seeds of the p50 over problems of that seed's run (the spread of
  the headline). solved_rate: fraction of problems whose median run found a path (at least half of its runs;
  "unsolved" names the others); runs_solved_rate: over the runs made. setup_us_p50: ArmPath.setup_seconds
  (building the call's collision model). grpc_ms_p50 / _p95: client wall time of a PlanArmPath call.
- search_us_p50 / _p95: the same runs' ArmPath.search_seconds (start and goal checks, the straight segment and
  RRT-Connect, without shortcutting and timing: what VAMP's evaluate_mbm.py calls planning time, apart from its
  simplification time); ompl_search_us_* likewise for the peer.
- ompl_*: the peer, planner="ompl_rrt_connect": OMPL's RRT-Connect with its default settings on the same
  collision checker, OMPL_REPS runs per problem (seeds 1..OMPL_REPS, 5 like ours), the same timeout and counting;
  ompl_us_p50_rep_range its spread over the seeds. speedup_vs_ompl_p50 =
  ompl_us_p50 / plan_us_p50; speedup_per_problem_p50: the median of the per-problem ratios.
- verified_fraction: of our planner's paths re-checked (VERIFY_REPS per problem: seeds 1..VERIFY_REPS), those
  PyBullet finds collision free (tests/bench/_mbm_check.py: conservative advancement, at most 1 mm of motion
  between checks near anything, self collision of the pairs panda.srdf does not disable), inside the URDF's joint
  limits, starting at the start and ending at the goal (1e-9 rad); the first failures in "unverified".
  ompl_verified_fraction likewise for the peer's paths. The re-check runs after the server has stopped.
- path_length_rad_mean / ompl_path_length_rad_mean: mean over all solved runs of the returned path's length (L2 in
  joint space, rad): what shortcutting buys, set beside VAMP's.
- vamp_* (only with GRASPSIM_MBM_VAMP_PYTHON, a Python that can `import vamp`; else vamp_measured is false): VAMP
  itself (vamp-planner 0.6.4, RRT-Connect and its simplifier with their defaults, as its evaluate_mbm.py runs them:
  tests/bench/_vamp_mbm.py) on the same problems.txt, REPS runs per problem, after our server has stopped, in the
  same bench run. Its own geometry (its sphere model of the Panda; cylinders as capsules, boxes in "box") and its
  own fixed-resolution motion check, so not the same checker: the field's anchor, not a like-for-like checker
  comparison. vamp_search_us_*: its planning time (our search_us_*); vamp_plan_us_*: planning plus simplification
  (our plan_us_*), each the median over a problem's runs, a problem VAMP calls invalid or a run it does not solve
  counted as TIMEOUT_S, with vamp_search_us_p50_rep_range / vamp_plan_us_p50_rep_range (as plan_us_p50_rep_range,
  over VAMP's REPS runs: the sampler continues from run to run, as evaluate_mbm.py has it); vamp_simplify_us_p50;
  vamp_solved_rate over all problems; vamp_path_length_rad_mean;
  speedup_search_vs_vamp_p50 = vamp_search_us_p50 / search_us_p50 and speedup_vs_vamp_p50 = vamp_plan_us_p50 /
  plan_us_p50 (above 1: ours faster); vamp_verified_fraction (and the other verify keys with the vamp_ prefix):
  its simplified paths of runs 1..VERIFY_REPS re-checked by _verify like ours, between the path's own end points
  (VAMP keeps configurations in float32, so they differ from the problem's by up to vamp_endpoint_error_rad_max;
  reported, not counted). vamp_version, vamp_motion_resolution (its fixed motion-check resolution). Per scene
  vamp_search_us_p50 and vamp_plan_us_p50.
- vamp_published_*: the figures quoted in issue 20 (35 µs published; 85 µs / 1.06 ms on a machine like ours).

Environment: GRASPSIM_MBM_REPS (5), GRASPSIM_MBM_OMPL_REPS (5), GRASPSIM_MBM_PROBLEMS_PER_SCENE (100),
GRASPSIM_MBM_TIMEOUT_S (10), GRASPSIM_MBM_VERIFY_REPS (1; 0 = no PyBullet check), GRASPSIM_MBM_VAMP_PYTHON (unset:
VAMP not run). The full run takes about 8.5 min on 2 cores, most of it the timeouts of the few problems nobody
solves (and 1 min of PyBullet); GRASPSIM_MBM_PROBLEMS_PER_SCENE=10 gives a look in about 20 s.
"""
import importlib.util
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from _harness import REPO, Server, log


def _load_data_module():
    """tests/data/mbm.py, the problems' fetcher and parser (imported by path: this module is "mbm" too)."""
    spec = importlib.util.spec_from_file_location("mbm_data", REPO / "tests" / "data" / "mbm.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["mbm_data"] = module
    spec.loader.exec_module(module)
    return module


mbm = _load_data_module()

ROBOT = "panda"
TIP = f"{ROBOT}/panda_hand"
FINGER_OPEN = 0.04   # m, set only when the model's finger joints are prismatic (VAMP's are fixed at 0.065)
REPS = int(os.environ.get("GRASPSIM_MBM_REPS", "5"))
OMPL_REPS = int(os.environ.get("GRASPSIM_MBM_OMPL_REPS", "5"))
PER_SCENE = int(os.environ.get("GRASPSIM_MBM_PROBLEMS_PER_SCENE", "100"))
TIMEOUT_S = float(os.environ.get("GRASPSIM_MBM_TIMEOUT_S", "10"))
VERIFY_REPS = min(REPS, int(os.environ.get("GRASPSIM_MBM_VERIFY_REPS", "1")))
PEER = "ompl_rrt_connect"
VAMP_PYTHON = os.environ.get("GRASPSIM_MBM_VAMP_PYTHON", "")
MAX_MESSAGES = 12


def _pose(o):
    """graspsim pose [x y z qw qx qy qz] of an obstacle (problems.txt has x y z w order)."""
    qx, qy, qz, qw = o.orientation
    return [*o.position, qw, qx, qy, qz]


def _setup_scene(client, problem, urdf: Path, fingers: dict) -> str:
    scene = client.create_scene(f"mbm {problem.name}").id
    client.add_robot(scene, ROBOT, path=str(urdf))
    if fingers:
        client.set_joint_positions(scene, fingers)
    for o in problem.obstacles:
        shape = {"box": dict(box=list(o.size)), "cylinder": dict(cylinder=list(o.size)),
                 "sphere": dict(sphere=o.size[0])}[o.kind]
        client.add_object(scene, o.id, pose=_pose(o), is_static=True, **shape)
    return scene


def _movable_fingers(client, urdf: Path) -> dict:
    """{finger joint id: FINGER_OPEN} for the model's prismatic finger joints (none in VAMP's Panda files).
    Checks that the robot's base stands at the world origin, where the problems (and PyBullet) have it."""
    scene = client.create_scene("mbm fingers").id
    try:
        client.add_robot(scene, ROBOT, path=str(urdf))
        joints = {j.id: j.type for j in client.get_scene(scene).joints}
        base = client.get_body_poses(scene, [f"{ROBOT}/panda_link0"])[f"{ROBOT}/panda_link0"]
    finally:
        client.delete_scene(scene)
    if np.abs(base.position).max() > 0 or np.abs(base.orientation - [1, 0, 0, 0]).max() > 1e-12:
        raise RuntimeError(f"the robot's base is at {base}, not at the world origin")
    ids = [f"{ROBOT}/panda_finger_joint{k}" for k in (1, 2)]
    movable = {j: FINGER_OPEN for j in ids if joints.get(j) == "prismatic"}
    log(f"mbm: finger joints {[joints[j] for j in ids if j in joints]}"
        + (f", set to {FINGER_OPEN} m" if movable else ", left as the URDF has them"))
    return movable


def _plan(client, scene, problem, seed, planner, record, failures, searches):
    """One PlanArmPath; appends (seconds or None, setup s, client wall s) to record and its search seconds (or
    TIMEOUT_S) to searches; returns the ArmPath or None. The first failure message of each problem and planner
    goes to failures."""
    import graspsim
    started = time.perf_counter()
    try:
        path = client.plan_arm_path(scene, ROBOT, start_positions=problem.start, goal_positions=problem.goal,
                                    tip_body=TIP, timeout=TIMEOUT_S, seed=seed, planner=planner,
                                    call_timeout=TIMEOUT_S + 30)
    except graspsim.GraspsimError as err:
        record.append((None, None, time.perf_counter() - started))
        searches.append(TIMEOUT_S)
        failures.setdefault((problem.name, planner or "ours"), f"seed {seed}: {err.code.name}: {err.message[:300]}")
        return None
    record.append((path.seconds, path.setup_seconds, time.perf_counter() - started))
    searches.append(path.search_seconds)
    return path


def _runs(client, scene, problem, planner, reps, record, failures, keep, searches):
    """reps runs (seeds 1..reps); once more than half are unsolved the median is the timeout whatever the rest
    do: those are skipped (recorded as (None, None, None)). keep(seed, path) gets every path."""
    for seed in range(1, reps + 1):
        if 2 * sum(s is None for s, _, _ in record) > reps:
            record.append((None, None, None))
            searches.append(TIMEOUT_S)
            continue
        path = _plan(client, scene, problem, seed, planner, record, failures, searches)
        if path is not None:
            keep(seed, path)


def _per_problem(runs):
    """Median planning time (s) of each problem's runs, an unsolved (or skipped) run counting as TIMEOUT_S."""
    return np.array([np.median([TIMEOUT_S if s is None else s for s, _, _ in r]) for r in runs])


def _solved(runs) -> float:
    """Fraction of problems solved: at least half of a problem's runs found a path (its median time is a path's)."""
    return round(sum(2 * sum(s is not None for s, _, _ in r) >= len(r) for r in runs) / max(1, len(runs)), 4)


def _run_stats(prefix, runs) -> dict:
    made = [s for r in runs for s, _, w in r if w is not None]
    return {f"{prefix}runs": len(made), f"{prefix}runs_solved_rate": round(sum(s is not None for s in made) /
                                                                            max(1, len(made)), 4),
            f"{prefix}runs_skipped": sum(w is None for r in runs for _, _, w in r)}


def _us(prefix, seconds, quantiles=(5, 50, 95)):
    out = {f"{prefix}_us_p{q}": round(float(np.percentile(seconds, q)) * 1e6, 1) for q in quantiles}
    out[f"{prefix}_us_max"] = round(float(np.max(seconds)) * 1e6, 1)
    return out


def _rep_range(runs, reps):
    """[min, max] µs over the seeds of the p50 over problems of that seed's runs (unsolved or skipped: timeout)."""
    by_seed = [np.median([r[k][0] if r[k][0] is not None else TIMEOUT_S for r in runs]) for k in range(reps)]
    return [round(float(min(by_seed)) * 1e6, 1), round(float(max(by_seed)) * 1e6, 1)]


def _length(waypoints) -> float:
    """L2 length in joint space, rad."""
    return float(np.linalg.norm(np.diff(np.asarray(waypoints, dtype=np.float64), axis=0), axis=1).sum())


def _ordered(path, arm_ids):
    """The path's waypoints as columns panda_joint1..7."""
    columns = [path.joint_ids.index(j) for j in arm_ids]
    return path.waypoints[:, columns]


def _plan_all(problems, urdf: Path):
    """Every problem through one server: per problem the runs of ours and of the peer ((seconds | None, setup s,
    wall s) each), the paths to re-check ((problem, seed, waypoints) per planner), failure messages, and per planner
    every solved run's path length."""
    import graspsim
    arm_ids = [f"{ROBOT}/{j}" for j in mbm.ARM_JOINTS]
    ours, peer, failures, planners = [], [], {}, set()
    searches = {"ours": [], "ompl": []}  # per problem: each run's search seconds
    paths = {"ours": [], "ompl": []}
    lengths = {"ours": [], "ompl": []}  # every solved run's path length, rad
    started = time.perf_counter()

    def keep(name):
        def add(seed, path):
            if name == "ompl" and path.planner != PEER:
                raise RuntimeError(f"asked for planner {PEER}, the server ran {path.planner!r}")
            planners.add(path.planner)
            waypoints = _ordered(path, arm_ids)
            lengths[name].append(_length(waypoints))
            if seed <= VERIFY_REPS:
                paths[name].append((problem, seed, waypoints))
        return add

    with Server() as server, graspsim.connect(server.address) as client:
        fingers = _movable_fingers(client, urdf)
        for n, problem in enumerate(problems):
            scene = _setup_scene(client, problem, urdf, fingers)
            ours.append([])
            peer.append([])
            searches["ours"].append([])
            searches["ompl"].append([])
            _runs(client, scene, problem, "", REPS, ours[-1], failures, keep("ours"), searches["ours"][-1])
            _runs(client, scene, problem, PEER, OMPL_REPS, peer[-1], failures, keep("ompl"), searches["ompl"][-1])
            client.delete_scene(scene)
            if n + 1 == len(problems) or problems[n + 1].scene != problem.scene:
                mine = [r for r, p in zip(ours, problems) if p.scene == problem.scene]
                theirs = [r for r, p in zip(peer, problems) if p.scene == problem.scene]
                line = f"mbm: {problem.scene}: solved {_solved(mine):.3f}, median " \
                       f"{np.median(_per_problem(mine)) * 1e6:.0f} µs"
                if OMPL_REPS:
                    line += f"; {PEER} solved {_solved(theirs):.3f}, median " \
                            f"{np.median(_per_problem(theirs)) * 1e6:.0f} µs"
                log(f"{line} ({time.perf_counter() - started:.0f} s so far)")
        exit_code = server.stop()
    return ours, peer, paths, failures, sorted(planners), exit_code, searches, lengths


def _unsolved(problems, runs):
    return [p.name for p, r in zip(problems, runs) if 2 * sum(s is not None for s, _, _ in r) < len(r)]


def run():
    load_before = round(os.getloadavg()[0], 2)
    panda = mbm.fetch()
    problems = [p for scene in mbm.problems_by_scene(mbm.read_problems_txt(panda / "problems.txt")).values()
                for p in scene[:PER_SCENE]]
    log(f"mbm: {len(problems)} problems, {REPS} runs each (graspsim), {OMPL_REPS} ({PEER}), timeout {TIMEOUT_S} s; "
        f"PyBullet re-check of {VERIFY_REPS} path(s) per problem and planner")
    started = time.perf_counter()
    ours, peer, paths, failures, planners, exit_code, searches, lengths = _plan_all(problems,
                                                                                   panda / "panda_spherized.urdf")
    plan_s = time.perf_counter() - started

    per_problem = _per_problem(ours)
    figures = {"problems": len(problems), "reps": REPS, "ompl_reps": OMPL_REPS, "timeout_s": TIMEOUT_S,
               "planners": planners, "solved_rate": _solved(ours), **_run_stats("", ours), **_us("plan", per_problem)}
    figures["plan_us_p50_rep_range"] = _rep_range(ours, REPS)
    setups = [u for r in ours for _, u, _ in r if u is not None]
    walls = [w for r in ours for _, _, w in r if w is not None]
    figures["setup_us_p50"] = round(float(np.median(setups)) * 1e6, 1) if setups else None
    figures["grpc_ms_p50"] = round(float(np.median(walls)) * 1e3, 3)
    figures["grpc_ms_p95"] = round(float(np.percentile(walls, 95)) * 1e3, 3)
    search = np.array([np.median(r) for r in searches["ours"]])
    figures.update(_us("search", search, (50, 95)))
    if OMPL_REPS > 0:
        search_peer = np.array([np.median(r) for r in searches["ompl"]])
        figures.update(_us("ompl_search", search_peer, (50, 95)))
        figures["speedup_search_vs_ompl_p50"] = round(figures["ompl_search_us_p50"] / figures["search_us_p50"], 2)
    if OMPL_REPS > 0:
        per_problem_peer = _per_problem(peer)
        figures.update(_us("ompl", per_problem_peer, (50, 95)))
        figures["ompl_solved_rate"] = _solved(peer)
        figures["ompl_us_p50_rep_range"] = _rep_range(peer, OMPL_REPS)
        figures.update(_run_stats("ompl_", peer))
        figures["speedup_vs_ompl_p50"] = round(figures["ompl_us_p50"] / figures["plan_us_p50"], 2)
        figures["speedup_per_problem_p50"] = round(float(np.median(per_problem_peer / per_problem)), 2)
    per_scene = {}
    for scene in mbm.SCENES:
        idx = [k for k, p in enumerate(problems) if p.scene == scene]
        if not idx:
            continue
        per_scene[scene] = {"solved_rate": _solved([ours[k] for k in idx]),
                            "plan_us_p50": round(float(np.median(per_problem[idx])) * 1e6, 1),
                            "plan_us_p95": round(float(np.percentile(per_problem[idx], 95)) * 1e6, 1)}
        if OMPL_REPS > 0:
            per_scene[scene]["ompl_solved_rate"] = _solved([peer[k] for k in idx])
            per_scene[scene]["ompl_us_p50"] = round(float(np.median(per_problem_peer[idx])) * 1e6, 1)
    figures["path_length_rad_mean"] = round(float(np.mean(lengths["ours"])), 4) if lengths["ours"] else None
    if OMPL_REPS > 0 and lengths["ompl"]:
        figures["ompl_path_length_rad_mean"] = round(float(np.mean(lengths["ompl"])), 4)
    figures["vamp_measured"] = bool(VAMP_PYTHON)
    if VAMP_PYTHON:
        figures.update(_vamp(panda, problems, figures, per_scene, paths))
    figures["per_scene"] = per_scene
    figures["unsolved"] = _unsolved(problems, ours)
    figures["ompl_unsolved"] = _unsolved(problems, peer) if OMPL_REPS > 0 else []
    figures["failures"] = [f"{name} {planner} {message}"
                           for (name, planner), message in list(failures.items())[:MAX_MESSAGES]]
    figures["plan_phase_s"] = round(plan_s, 1)
    if VERIFY_REPS > 0:
        figures.update(_verify(panda, paths))
    figures["load_avg_1m"] = [load_before, round(os.getloadavg()[0], 2)]
    figures["vamp_published_us_p50"] = 35
    figures["vamp_published_like_ours_us_p50"] = 85
    figures["vamp_published_like_ours_us_p95"] = 1060
    figures["vamp_published_note"] = (
        "quoted from issue 20: VAMP's published median on the MBM Panda problems is 35 µs; its 85 µs median and "
        "1.06 ms p95 were measured on a machine like ours. Both are VAMP's planning time without its "
        "simplification: beside our search_us_*; vamp_search_us_* / vamp_plan_us_* are VAMP run here")
    return figures, exit_code


def _verify(panda: Path, paths) -> dict:
    """PyBullet's verdict on the collected paths of each planner (after the server has stopped)."""
    from _mbm_check import PandaChecker
    started = time.perf_counter()
    checker = PandaChecker(panda / "panda_spherized.urdf", panda / "panda.srdf", mbm.ARM_JOINTS)
    out, current = {}, None
    for planner, runs in paths.items():
        prefix = "" if planner == "ours" else f"{planner}_"
        good, samples, unverified = 0, 0, []
        for n, (problem, seed, waypoints) in enumerate(runs):
            if problem is not current:
                checker.set_obstacles(problem.obstacles)
                current = problem
            # VAMP keeps configurations in float32: its paths are checked between their own end points (how far
            # those are from the problem's is vamp_endpoint_error_rad_max).
            start, goal = ((waypoints[0], waypoints[-1]) if planner == "vamp" else
                           (np.array(problem.start), np.array(problem.goal)))
            result = checker.check_path(waypoints, start, goal)
            samples += result.samples
            good += result.ok
            if not result.ok and len(unverified) < MAX_MESSAGES:
                unverified.append(f"{problem.name} seed {seed}: " + "; ".join(result.problems[:3]))
            if (n + 1) % 100 == 0:
                log(f"mbm: PyBullet re-check ({planner}) {n + 1}/{len(runs)}: {good} collision free "
                    f"({time.perf_counter() - started:.0f} s)")
        out.update({f"{prefix}verified_paths": len(runs),
                    f"{prefix}verified_fraction": round(good / len(runs), 4) if runs else None,
                    f"{prefix}verify_samples_per_path": round(samples / max(1, len(runs)), 1),
                    f"{prefix}unverified": unverified})
    out["verify_s"] = round(time.perf_counter() - started, 1)
    return out


def _vamp(panda: Path, problems, ours: dict, per_scene: dict, paths: dict) -> dict:
    """VAMP's runs (tests/bench/_vamp_mbm.py under VAMP_PYTHON) on the same problems and their figures; its first
    VERIFY_REPS runs' paths go to paths["vamp"] for _verify. `ours` and `per_scene` give the keys to set VAMP's
    beside."""
    started = time.perf_counter()
    listing = panda / "problems_vamp.txt"   # the problems run here (PER_SCENE may cut the 700)
    mbm.write_problems_txt(problems, listing)
    reply = subprocess.run([VAMP_PYTHON, str(Path(__file__).with_name("_vamp_mbm.py")), str(listing), str(REPS)],
                           check=True, capture_output=True, text=True)
    answer = json.loads(reply.stdout)
    results = answer["problems"]
    if [r["name"] for r in results] != [p.name for p in problems]:
        raise RuntimeError("VAMP's answers are not for the problems asked")
    vamp_s = time.perf_counter() - started

    def as_ours(with_simplify):
        """VAMP's runs shaped as _plan_all's for ours: per problem REPS (seconds | None, None, None), an invalid
        problem's all None, so that _per_problem, _rep_range and _solved count them as they count ours."""
        return [[((run["plan_us"] + (run["simplify_us"] if with_simplify else 0)) / 1e6
                  if run["waypoints"] is not None else None, None, None) for run in r["runs"]]
                or [(None, None, None)] * REPS for r in results]

    search_runs, plan_runs = as_ours(False), as_ours(True)
    search, plan = _per_problem(search_runs), _per_problem(plan_runs)
    solved = [(problem, k + 1, np.array(run["waypoints"], dtype=np.float64)) for problem, r in zip(problems, results)
              for k, run in enumerate(r["runs"]) if run["waypoints"] is not None]  # (problem, seed, waypoints)
    paths["vamp"] = [entry for entry in solved if entry[1] <= VERIFY_REPS]
    out = {"vamp_version": answer["vamp_version"], "vamp_motion_resolution": answer["resolution"],
           **_us("vamp_search", search, (50, 95)), **_us("vamp_plan", plan, (50, 95))}
    simplify = [run["simplify_us"] for r in results for run in r["runs"] if run["waypoints"] is not None]
    out["vamp_search_us_p50_rep_range"] = _rep_range(search_runs, REPS)
    out["vamp_plan_us_p50_rep_range"] = _rep_range(plan_runs, REPS)
    out["vamp_simplify_us_p50"] = round(float(np.median(simplify)), 1) if simplify else None
    out["vamp_solved_rate"] = _solved(plan_runs)
    out["vamp_invalid"] = [r["name"] for r in results if not r["valid"]]
    out["vamp_path_length_rad_mean"] = round(float(np.mean([_length(w) for _, _, w in solved])), 4) if solved else None
    out["speedup_search_vs_vamp_p50"] = round(out["vamp_search_us_p50"] / ours["search_us_p50"], 2)
    out["speedup_vs_vamp_p50"] = round(out["vamp_plan_us_p50"] / ours["plan_us_p50"], 2)
    out["vamp_endpoint_error_rad_max"] = max((float(max(np.abs(w[0] - problem.start).max(),
                                                        np.abs(w[-1] - problem.goal).max()))
                                              for problem, _, w in paths["vamp"]), default=None)
    out["vamp_phase_s"] = round(vamp_s, 1)
    for scene, figures in per_scene.items():
        idx = [k for k, p in enumerate(problems) if p.scene == scene]
        figures["vamp_search_us_p50"] = round(float(np.median(search[idx])) * 1e6, 1)
        figures["vamp_plan_us_p50"] = round(float(np.median(plan[idx])) * 1e6, 1)
    log(f"mbm: VAMP search p50 {out['vamp_search_us_p50']} µs, with simplification {out['vamp_plan_us_p50']} µs")
    return out
