#!/usr/bin/env python3
"""Pick and place: a KUKA KR 5 sixx R850 with a Schunk PG70 on its flange moves a 5 cm cube across a table.

GraspService.PickAndPlace (docs/motion.md, "Pick and place") plans the PG70's grasp set on the cube (or reuses
the stored one), keeps the grasps the arm reaches without collision, plans the arm's paths (approach, lift,
transfer, place, retreat) and executes them in the dynamic simulation; the scene ends with the cube at the goal.
Prints the stages as they stream and the final object pose error, checked here from the scene's body poses.

    python3 pick_and_place.py [--server 127.0.0.1:50051] [--keep]
"""
import argparse
import sys

import numpy as np

import graspsim

TABLE_TOP_Z = 0.75   # m, the built-in table's top at the origin
CUBE_EDGE = 0.05     # m
ARM_BASE = [-0.45, 0.0, TABLE_TOP_Z, 1, 0, 0, 0]


def stage_printer():
    """on_progress callback printing each stage once, with the fraction at which it began."""
    seen = []

    def on_progress(stage: str, fraction: float) -> None:
        if not seen or seen[-1] != stage:
            seen.append(stage)
            print(f"  {fraction * 100:5.1f} %  {stage}")
    return on_progress


def pick_and_place(client: graspsim.Client, scene_id: str, arm_id: str, body_id: str, goal, **kwargs):
    """Runs PickAndPlace, prints the stages, the outcome and the object's pose error read back from the scene."""
    # The printed stages instead of a progress bar: the two on one terminal would garble each other.
    result = client.pick_and_place(scene_id, arm_id, body_id, goal, on_progress=stage_printer(), progress=False,
                                   **kwargs)
    end = client.get_body_poses(scene_id, [body_id])[body_id]
    goal = graspsim.as_pose(goal)
    error = float(np.linalg.norm(np.asarray(end.position) - np.asarray(goal.position)))
    dot = min(1.0, abs(float(np.dot(end.orientation, goal.orientation))))
    print(f"  grasp {result.grasp_index} of set {result.grasp_set_id[:12]}… ({result.reachable} reachable; "
          f"failed before it: {len(result.failures)}), grip {result.grip_force:.0f} N, "
          f"{result.simulated_seconds:.1f} s simulated")
    for failure in result.failures:
        print(f"  attempt failed: {failure}")
    print(f"  {body_id} ends {error * 1000:.1f} mm and {np.degrees(2 * np.arccos(dot)):.1f}° from the goal "
          f"(tolerance 10 mm, 10°): {'placed' if result.success else 'missed'}")
    return result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051", help="host:port of graspsim-server")
    parser.add_argument("--keep", action="store_true", help="keep the scene on the server (default: delete it)")
    args = parser.parse_args(argv)
    try:
        with graspsim.connect(args.server) as client:
            scene_id = client.create_scene("pick and place").id
            client.add_object(scene_id, "table", builtin="table")
            client.add_object(scene_id, "cube", builtin="cube_5cm",
                              pose=[0.05, 0.2, TABLE_TOP_Z + CUBE_EDGE / 2, 1, 0, 0, 0])
            client.add_robot(scene_id, "kr5", builtin="kuka_kr5_sixx_r850_pg70", base_pose=ARM_BASE)
            goal = [0.05, -0.2, TABLE_TOP_Z + CUBE_EDGE / 2, 1, 0, 0, 0]
            print(f"KR 5 + PG70 moves the cube from (0.05, 0.20) to (0.05, -0.20) on the table (scene {scene_id}):")
            pick_and_place(client, scene_id, "kr5", "cube", goal)
            if not args.keep:
                client.delete_scene(scene_id)
    except (graspsim.GraspsimError, OSError) as err:
        print(f"pick and place failed: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
