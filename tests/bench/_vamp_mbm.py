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
Output, one JSON object on stdout: VAMP's version and motion resolution; per problem (in input order) its name,
valid, and its REPS runs, each with planning and simplification microseconds (VAMP's own nanosecond timers; the
latter null when the run found no path) and the simplified path's waypoints (null likewise). mbm.py makes the
figures from them.
"""
import importlib.metadata
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


def main(problems_txt: str, reps: str) -> int:
    reps = int(reps)
    robot, rrtc, plan_settings, simplify_settings = vamp.configure_robot_and_planner_with_kwargs("panda", "rrtc")
    sampler = robot.halton()
    results = []
    for problem in _problems(Path(problems_txt)):
        env = vamp.problem_dict_to_vamp(_problem_dict(problem))
        entry = {"name": problem.name, "valid": bool(robot.validate(problem.start, env) and
                                                    robot.validate(problem.goal, env)), "runs": []}
        results.append(entry)
        if not entry["valid"]:
            continue
        sampler.reset()
        for _ in range(reps):
            planned = rrtc(problem.start, [problem.goal], env, plan_settings, sampler)
            run = {"plan_us": planned.nanoseconds / 1e3, "simplify_us": None, "waypoints": None}
            if planned.solved:
                simple = robot.simplify(planned.path, env, simplify_settings, sampler)
                run["simplify_us"] = simple.nanoseconds / 1e3
                run["waypoints"] = simple.path.numpy().astype(float).tolist()
            entry["runs"].append(run)
    json.dump({"vamp_version": importlib.metadata.version("vamp-planner"), "resolution": robot.resolution(),
               "problems": results}, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
