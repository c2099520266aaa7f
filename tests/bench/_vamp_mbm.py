"""VAMP on the MotionBenchMaker problems of tests/bench/mbm.py, as VAMP's own scripts/evaluate_mbm.py runs it: the
compiled Panda (VAMP's sphere model, the same as panda_spherized.urdf), RRT-Connect ("rrtc") and its simplifier
with their default settings, the Halton sampler reset per problem and continued over the runs of a problem.

Run by mbm.py under a Python that has `vamp` (vamp-planner 0.6.4; GRASPSIM_MBM_VAMP_PYTHON), never by the project's
venv: VAMP's build fetches its C++ dependencies from GitHub, which a CI machine need not reach, so VAMP is an
optional peer (docs/benchmarks.md, mbm, says how it was built).

    python _vamp_mbm.py PROBLEMS_TXT REPS

Input: the same problems.txt that the server's runs read (tests/data/mbm.py parses it; its obstacles turned into
VAMP's problem dictionary and through vamp.problem_dict_to_vamp, as VAMP's converter does from the same YAML:
cylinders as capsules, and as boxes in the "box" scene). Only VAMP's own start/goal test decides what is run: a
problem whose start or goal VAMP calls colliding is reported invalid, not planned (evaluate_mbm.py skips those).
Output, one JSON object on stdout: per problem (in input order) name, valid, and over its REPS runs each run's
planning and simplification microseconds (VAMP's own nanosecond timers), solved flags, path lengths (rad, L2 in
joint space, after simplification), and the first run's simplified waypoints for the PyBullet re-check.
"""
import importlib.util
import json
import sys
from pathlib import Path

import vamp
from vamp.transformations import euler_from_matrix, quaternion_matrix

HERE = Path(__file__).resolve().parent


def _problems(path: Path):
    spec = importlib.util.spec_from_file_location("mbm_data", HERE.parent / "data" / "mbm.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["mbm_data"] = module
    spec.loader.exec_module(module)
    return module.read_problems_txt(path)


def _problem_dict(problem) -> dict:
    """VAMP's problem dictionary (resources/problem_tar_to_pkl_json.py's form) of a parsed problem."""
    out = {"problem": problem.scene, "sphere": [], "cylinder": [], "box": []}
    for o in problem.obstacles:
        euler = list(euler_from_matrix(quaternion_matrix(list(o.orientation))))  # (x, y, z, w), as VAMP reads it
        if o.kind == "box":
            out["box"].append({"name": o.id, "position": list(o.position), "orientation_euler_xyz": euler,
                               "half_extents": [s / 2 for s in o.size]})
        elif o.kind == "cylinder":
            out["cylinder"].append({"name": o.id, "position": list(o.position), "orientation_euler_xyz": euler,
                                    "radius": o.size[0], "length": o.size[1]})
        else:
            out["sphere"].append({"name": o.id, "position": list(o.position), "radius": o.size[0]})
    return out


def _length(waypoints) -> float:
    return float(sum(sum((b - a) ** 2 for a, b in zip(p, q)) ** 0.5 for p, q in zip(waypoints, waypoints[1:])))


def main(problems_txt: str, reps: str) -> int:
    reps = int(reps)
    robot, rrtc, plan_settings, simplify_settings = vamp.configure_robot_and_planner_with_kwargs("panda", "rrtc")
    sampler = robot.halton()
    results = []
    for problem in _problems(Path(problems_txt)):
        env = vamp.problem_dict_to_vamp(_problem_dict(problem))
        entry = {"name": problem.name, "valid": bool(robot.validate(problem.start, env) and
                                                    robot.validate(problem.goal, env)),
                 "plan_us": [], "simplify_us": [], "solved": [], "length_rad": [], "waypoints": None}
        results.append(entry)
        if not entry["valid"]:
            continue
        sampler.reset()
        for rep in range(reps):
            planned = rrtc(problem.start, [problem.goal], env, plan_settings, sampler)
            entry["solved"].append(bool(planned.solved))
            entry["plan_us"].append(planned.nanoseconds / 1e3)
            if not planned.solved:
                entry["simplify_us"].append(None)
                entry["length_rad"].append(None)
                continue
            simple = robot.simplify(planned.path, env, simplify_settings, sampler)
            waypoints = simple.path.numpy().astype(float).tolist()
            entry["simplify_us"].append(simple.nanoseconds / 1e3)
            entry["length_rad"].append(_length(waypoints))
            if rep == 0:
                entry["waypoints"] = waypoints
    json.dump({"vamp_version": getattr(vamp, "__version__", "0.6.4"), "reps": reps,
               "resolution": robot.resolution(), "problems": results}, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
