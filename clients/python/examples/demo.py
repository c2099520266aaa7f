#!/usr/bin/env python3
"""graspsim demo: a Schunk PG70 gripper grasps a 5 cm cube on a table.

Stages: list the built-in models, build the scene with the open gripper around the cube, print what the
server holds (bodies, joints, tactile arrays, one live snapshot), read the same scene through the HTTP/JSON
gateway that Matlab and browsers use, then simulate: the cube settles, the PG70 closes on it under velocity
control with a current (force) limit, and the table is taken away while the fingers hold the cube. Last, the
tactile work cycle in a fresh scene (a PG70 on a vertical axis: approach, grasp under tactile force control,
lift, hold, move down, release; examples/tactile_cycle.py runs it at several coverages) with its summary, and
its plots when matplotlib is installed. Then shape completion and grasp planning: a simulated depth camera sees
the cube from one side, PerceptionService completes it by its symmetry (examples/shape_completion.py), the
completed mesh joins a table scene as an object, and the PG70's grasp set is planned on it (examples/
grasp_planning.py does all three hands on the true cube and draws them). Last, the hardware gateway
with emulated grippers (examples/hardware_gateway.py): commands through the server, an e-stop, and a PG70 move
beside its simulated twin with the surprise. Last, a KUKA KR 5 with the PG70 picks the completed cube up and
puts it 25 cm away, planned and executed in the dynamic simulation (examples/pick_and_place.py). And when the
`pybullet` package is installed, a robot nobody here wrote: pybullet_data's Franka Panda loaded from its URDF by
path (its meshes uploaded by the client), with the repairs the server made (docs/import.md), and arm paths
planned for it around a post in one PlanArmPaths call, graspsim's planner beside OMPL's (docs/motion.md). Then one
scene on three physics engines (SimulationParams.engine: graspsim, MuJoCo, Bullet): a ball rolling down 20°
against its closed form, and the tactile work cycle on each (docs/physics.md). And beyond one machine (docs/scaling.md): three servers started from --server-binary behind HAProxy, scenes routed by
id, one killed and restarted, a fourth added and the scenes rebalanced (examples/fleet.py). Exits non-zero on
any error.

    python3 demo.py --server 127.0.0.1:50051 --http http://127.0.0.1:8080 [--out DIR] [--server-binary PATH]
"""
import argparse
import json
import math
import shutil
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

import numpy as np

import graspsim
import fleet  # examples/fleet.py, next to this file
import grasp_planning  # examples/grasp_planning.py, next to this file
import hardware_gateway  # examples/hardware_gateway.py, next to this file
import pick_and_place  # examples/pick_and_place.py, next to this file
import shape_completion  # examples/shape_completion.py, next to this file
import tactile_cycle  # examples/tactile_cycle.py, next to this file

REPO = Path(__file__).resolve().parents[3]

TABLE_TOP_Z = 0.75        # m, top surface of the built-in table placed at the origin
CUBE_EDGE = 0.05          # m
GRIPPER_HEIGHT = 0.16     # m above the table top: fingertips 7 mm above it, the housing clear of the cube
FINGER_OPENING = 0.03     # m, finger_left_joint (finger_right_joint mimics it)
CLOSING_SPEED = 0.05      # m/s per finger (the PG70 reaches 0.082)
CURRENT_LIMIT = 2.0       # A: the PG70 drive's force limit, about 114 N here (200 N at its rated 3.5 A)
POINTING_DOWN = graspsim.quaternion_about_axis([1, 0, 0], np.pi)  # gripper z (approach) = world -z


def list_models(client: graspsim.Client) -> None:
    print("built-in models:")
    for model in client.builtin_models():
        print(f"  {model.kind:<6} {model.name:<22} {model.description}")


def build_scene(client: graspsim.Client) -> str:
    """Creates scene "demo": the table, the cube resting on it, the gripper around the cube; returns its id."""
    scene = client.create_scene("demo")  # a SceneSummary: passed on as the scene itself
    client.add_object(scene, "table", builtin="table")
    client.add_object(scene, "cube_5cm", builtin="cube_5cm", pose=[0, 0, TABLE_TOP_Z + CUBE_EDGE / 2, 1, 0, 0, 0])
    gripper_pose = graspsim.Pose([0, 0, TABLE_TOP_Z + GRIPPER_HEIGHT], POINTING_DOWN)
    client.add_robot(scene, "pg70", builtin="schunk_pg70", base_pose=gripper_pose)
    print(f"\nscene {scene.name!r} created: id {scene.id}")
    return scene.id


def open_gripper(client: graspsim.Client, scene_id: str) -> None:
    revision = client.set_joint_positions(scene_id, {"pg70/finger_left_joint": FINGER_OPENING})
    print(f"gripper opened to {FINGER_OPENING * 1000:.0f} mm per finger (revision {revision})")


def format_pose(pose: graspsim.Pose) -> str:
    x, y, z = pose.position
    return f"p=({x:+.4f}, {y:+.4f}, {z:+.4f}) m  q=({', '.join(f'{v:+.3f}' for v in pose.orientation)})"


def print_bodies(scene: graspsim.Scene) -> None:
    print(f"\nbodies ({len(scene.bodies)}):")
    for body in scene.bodies:
        print(f"  {body.id:<18} {body.motion:<11} {body.inertial.mass:7.3f} kg  {format_pose(body.pose)}")


def print_joints(scene: graspsim.Scene) -> None:
    print(f"\njoints ({len(scene.joints)}):")
    for joint in scene.joints:
        unit = "m" if joint.type == "prismatic" else "rad"
        follows = f"  mimics {joint.mimic.joint_id}" if joint.mimic else ""
        limits = f"[{joint.lower:.4f}, {joint.upper:.4f}]"
        print(f"  {joint.id:<24} {joint.type:<9} {joint.position:.4f} {unit}  limits {limits}{follows}")


def print_tactile_arrays(scene: graspsim.Scene) -> None:
    print(f"\ntactile arrays ({len(scene.tactile_arrays)}):")
    for pad in scene.tactile_arrays:
        shape = "curved" if pad.bend_radius_x or pad.bend_radius_y else "flat"
        print(f"  {pad.id:<16} on {pad.body_id:<18} {pad.rows} rows x {pad.cols} cols, pitch {pad.pitch * 1000:.1f} mm,"
              f" {shape}, {pad.rows * pad.cols * pad.subdivision ** 2 * (2 if pad.elements == 'face_centres' else 1)}"
              f" sensing elements ({pad.elements})")


def print_snapshot(client: graspsim.Client, scene_id: str) -> None:
    with client.watch_scene(scene_id) as watch:
        snap = next(watch)
    print(f"\nsnapshot {snap.sequence} (revision {snap.revision}, t = {snap.time:.3f} s): "
          f"{len(snap.body_ids)} bodies, {len(snap.joint_ids)} joints")
    for body_id, row in zip(snap.body_ids, snap.poses):
        print(f"  {body_id:<18} z = {row[2]:.4f} m")
    for joint_id, value in zip(snap.joint_ids, snap.joint_positions):
        print(f"  {joint_id:<24} {value:.4f}")


def read_over_http(http_url: str, scene_id: str) -> None:
    """The gateway serves every RPC as JSON: the same scene, as a Matlab or browser client sees it."""
    with urllib.request.urlopen(f"{http_url}/v1", timeout=10) as response:
        methods = sum(len(service["methods"]) for service in json.load(response)["services"])
    request = urllib.request.Request(f"{http_url}/v1/SceneService/GetScene",
                                     data=json.dumps({"scene_id": scene_id}).encode(),
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=10) as response:
        summary = json.load(response)["summary"]
    print(f"\nHTTP gateway {http_url}: {methods} methods; POST /v1/SceneService/GetScene -> "
          f"{summary['body_count']} bodies, {summary['robot_count']} robot, revision {summary['revision']}")


def show_viewer(http_url: str, scene_id: str) -> None:
    """The browser viewer of the same scene on the same port (docs/viewer.md): any number of people can watch."""
    url = graspsim.viewer_url(scene_id, http_url)
    with urllib.request.urlopen(url, timeout=10):  # the page is served (an error raises)
        pass
    print(f"browser viewer: {url} (every scene: {http_url}/view; --keep keeps this one to watch)")


def cube_state(client: graspsim.Client, scene_id: str):
    cube = next(b for b in client.get_scene(scene_id).bodies if b.id == "cube_5cm")
    return cube.pose.position[2], cube.sleeping


def simulate_grasp(client: graspsim.Client, scene_id: str) -> None:
    """The dynamic simulation: soft contacts with LuGre friction, the PG70's DC-motor drive."""
    params = client.get_simulation_params(scene_id)
    print(f"\nsimulation: dt = {params.time_step * 1000:.1f} ms, contact k = {params.contact.stiffness:.0f} N/m")
    step = client.step_simulation(scene_id, duration=0.7)
    z, sleeping = cube_state(client, scene_id)
    print(f"  t = {step.time:.2f} s  cube at rest on the table: z = {z:.5f} m "
          f"({(TABLE_TOP_Z + CUBE_EDGE / 2 - z) * 1e6:.1f} um soft-contact penetration), asleep: {sleeping}")
    client.set_actuator(scene_id, "pg70/finger_left_joint", "velocity", -CLOSING_SPEED, current_limit=CURRENT_LIMIT)
    step = client.step_simulation(scene_id, duration=0.8)
    finger = client.get_joint_positions(scene_id)["pg70/finger_left_joint"]
    print(f"  t = {step.time:.2f} s  PG70 closed at {CLOSING_SPEED * 1000:.0f} mm/s, {CURRENT_LIMIT} A limit: "
          f"finger at {finger * 1000:.2f} mm, {step.contacts} contact points")
    client.remove_body(scene_id, "table")
    started = time.perf_counter()
    step = client.step_simulation(scene_id, duration=1.0)
    rate = step.steps / (time.perf_counter() - started)
    held_z, _ = cube_state(client, scene_id)
    print(f"  t = {step.time:.2f} s  table removed: the cube moved {(z - held_z) * 1e6:.1f} um in 1 s, held by "
          f"friction ({rate:.0f} steps/s with {step.contacts} contacts)")


def run_work_cycle(client: graspsim.Client, out) -> None:
    """The tactile work cycle at full coverage (a scene of its own, deleted after), recorded, its summary and plots."""
    print("\ntactile work cycle (schunk_pg70_on_z_axis picks the cube, coverage 1.0):")
    name = f"demo-work-cycle-{time.strftime('%Y%m%dT%H%M%S')}.mcap"
    result = tactile_cycle.run_cycle(client, 1.0, hold_time=0.5, record=name)
    tactile_cycle.print_summary("coverage 100 %", result)
    show_recording(client, next(r for r in client.list_recordings() if r.name == name), out)
    if not tactile_cycle.matplotlib_available():
        print("  (matplotlib not installed: no plots; pip install 'graspsim[plot]')")
        return
    out = Path(out) if out is not None else Path(tempfile.mkdtemp(prefix="graspsim-demo-"))
    for path in tactile_cycle.write_figures({"coverage 100 %": result}, out, prefix="demo-work-cycle"):
        print(f"  plot: {path}")


def show_recording(client: graspsim.Client, info, out) -> None:
    """The work cycle's recording: where it is, how to open it, and a replay of its last frame."""
    print(f"  recorded: {info.path} ({info.frames} frames, {info.messages} messages, {info.bytes / 1e6:.2f} MB, "
          f"{info.dropped_frames} dropped)")
    print(f"    open it in Foxglove (app.foxglove.dev or the desktop app: Open local file), 3D panel on /scene and /tf,")
    print(f"    Image panel on /tactile/cell/pad_left; ROS 2 bag beside it: {info.ros2_path} (ros2 bag play, rosbags)")
    local = Path(out if out is not None else tempfile.mkdtemp(prefix="graspsim-demo-")) / info.name
    client.download_recording(info.name, local)
    replay = client.replay_recording(info.name)
    client.seek_replay(replay.scene_id, info.name, len(replay.frame_times) - 1)
    cube = client.get_body_poses(replay.scene_id, ["cube"])["cube"]
    print(f"  downloaded to {local}; replayed into {replay.scene_id}: {len(replay.frame_times)} frames, "
          f"cube at the last one {format_pose(cube)}")
    client.delete_scene(replay.scene_id)


def plan_grasps(client: graspsim.Client) -> str:
    """Returns the scene with the completed cube (cube_seen) on the table, for pick_and_place_completed."""
    print("\nshape completion (the cube seen from one side by a simulated depth camera):")
    scene_id = client.create_scene("completed cube").id
    client.add_object(scene_id, "table", builtin="table")
    cube_v, cube_t = graspsim.meshes.box_mesh([CUBE_EDGE] * 3)
    cube_v = np.asarray(cube_v) + [0, 0, TABLE_TOP_Z + CUBE_EDGE / 2]
    camera, depth, mask = shape_completion.seen_from_one_side(cube_v, cube_t, TABLE_TOP_Z)
    shape = client.complete_shape(camera, depth=depth, intrinsics=shape_completion.INTRINSICS, mask=mask,
                                  table_pose=[0, 0, TABLE_TOP_Z, 1, 0, 0, 0], refinements=2,
                                  add_to_scene_id=scene_id, object_name="cube_seen", object_mass=0.1)
    size = shape.vertices.max(axis=0) - shape.vertices.min(axis=0)
    print(f"  {int(mask.sum())} pixels seen; completed into {len(shape.triangles)} triangles, "
          f"{np.round(size * 1e3).astype(int).tolist()} mm across (true: 50 mm), in {shape.timings_ms['total']:.0f} ms;"
          f" added as {shape.body_id!r}")
    print("grasp planning (the completed cube on the table, bounding-box candidates, stored for the next run):")
    grasp_planning.plan(client, scene_id, "schunk_pg70", body_id=shape.body_id)
    return scene_id


def pick_and_place_completed(client: graspsim.Client, scene_id: str) -> None:
    """A KUKA KR 5 with the PG70 on its flange moves the completed cube 25 cm along the table, planned and
    executed in the dynamic simulation (examples/pick_and_place.py)."""
    client.add_robot(scene_id, "kr5", builtin="kuka_kr5_sixx_r850_pg70",
                     base_pose=[-0.45, 0, TABLE_TOP_Z, 1, 0, 0, 0])
    start = client.get_body_poses(scene_id, ["cube_seen"])["cube_seen"]
    goal = np.concatenate([np.asarray(start.position) + [0, -0.25, 0], start.orientation])
    print("\npick and place (KR 5 + PG70 moves the completed cube 25 cm to the right):")
    pick_and_place.pick_and_place(client, scene_id, "kr5", "cube_seen", goal)
    client.delete_scene(scene_id)


def load_public_robot(client) -> None:
    """pybullet_data's Franka Panda by path, beside the built-ins, when the pybullet wheel is installed; arm paths
    planned for it around a post."""
    try:
        import pybullet_data
    except ImportError:
        print("\npublic robot files: pybullet not installed (pip install pybullet), skipped")
        return
    path = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"
    scene_id = client.create_scene("public-robot").id
    reply = client.add_robot(scene_id, "panda", path=str(path))
    mass = sum(body.inertial.mass for body in reply.bodies)
    print(f"\npublic robot file {path.name} (pybullet_data) loaded by path: {len(reply.bodies)} links, "
          f"{len(reply.joints)} joints, {mass:.2f} kg; {len(reply.warnings)} repair(s):")
    for warning in reply.warnings:
        print(f"  {warning.element} = {warning.value}: {warning.action}")
    hand = client.get_body_poses(scene_id, ["panda/panda_hand"])["panda/panda_hand"]
    print(f"  panda_hand at {format_pose(hand)} with every joint at 0")
    # Arm paths for it around a post, in one batch call: graspsim's RRT-Connect and OMPL's on the same checker.
    client.add_object(scene_id, "post", box=[0.08, 0.08, 1.0], pose=[0.3, -0.3, 0.5, 1, 0, 0, 0], is_static=True)
    ready = [0, -0.785, 0, -2.356, 0, 1.571, 0.785]
    turned = [-1.57, -0.785, 0, -2.356, 0, 1.571, 0.785]
    problems = [dict(scene_id=scene_id, arm_id="panda", tip_body="panda/panda_hand", start_positions=ready,
                     goal_positions=turned, planner=planner, seed=1) for planner in ("rrt_connect", "ompl_rrt_connect")]
    for result in client.plan_arm_paths(problems):
        if isinstance(result, graspsim.GraspsimError):
            raise result
        print(f"  arm path around a post ({result.planner}): {len(result.waypoints)} waypoints, "
              f"{result.duration:.2f} s of motion, planned in {result.seconds * 1e3:.2f} ms "
              f"({result.checks} configurations checked)")
    client.delete_scene(scene_id)


def three_engines(client: graspsim.Client) -> None:
    """One scene description on graspsim's engine, MuJoCo and Bullet (SimulationParams.engine): a ball rolling
    down a 20° incline (gravity tilted over a level floor), against the closed form 5/7 g sin θ."""
    theta, radius = math.radians(20), 0.05
    expected = 5 / 7 * 9.81 * math.sin(theta)
    print(f"\none scene, three physics engines: a ball rolling down 20°, closed form {expected:.4f} m/s²:")
    for engine in ("graspsim", "mujoco", "bullet"):
        scene_id = client.create_scene(f"rolling on {engine}").id
        client.set_simulation_params(scene_id, engine=engine, gravity=(9.81 * math.sin(theta), 0,
                                                                       -9.81 * math.cos(theta)))
        client.add_object(scene_id, "floor", box=[20, 1, 0.1], pose=[0, 0, -0.05, 1, 0, 0, 0], is_static=True,
                          friction=[1, 1])
        client.add_object(scene_id, "ball", sphere=radius, mass=1.0, pose=[0, 0, radius, 1, 0, 0, 0],
                          friction=[1, 1])
        client.step_simulation(scene_id, duration=0.1)
        v0 = client.get_body_velocities(scene_id, ["ball"])["ball"].linear[0]
        client.step_simulation(scene_id, duration=1.0)
        v1 = client.get_body_velocities(scene_id, ["ball"])["ball"].linear[0]
        print(f"  {engine:<9} {v1 - v0:.4f} m/s² ({(v1 - v0 - expected) / expected * 100:+.3f} %)")
        client.delete_scene(scene_id)
    # The tactile work cycle on each engine: the pads read through the engine's contacts (docs/physics.md).
    print("the work cycle on each engine (PG70, 5 cm cube, lift 5 cm), pads read through its contacts:")
    for engine in ("graspsim", "mujoco", "bullet"):
        scene_id = tactile_cycle.build_cell(client, f"work cycle on {engine}")
        client.set_simulation_params(scene_id, engine=engine)
        result = client.run_work_cycle(scene_id, tactile_cycle.GRIPPER, tactile_cycle.CUBE, lift_height=0.05,
                                       progress=False)
        hold = [i for i, stage in enumerate(result.stage) if stage == "hold"]
        resting = tactile_cycle.TABLE_TOP_Z + tactile_cycle.CUBE_EDGE / 2
        print(f"  {engine:<9} cube lifted {result.object_position[hold[-1], 2] - resting:.4f} m, pad sums "
              f"{result.left_sum[hold[-1]]:.0f} / {result.right_sum[hold[-1]]:.0f} while held")
        client.delete_scene(scene_id)


def beyond_one_machine(server_binary: str) -> None:
    """A fleet of three servers behind HAProxy on this machine (examples/fleet.py), when haproxy and
    grpc-health-probe are installed (make go-tools); the servers are started from server_binary."""
    probe = REPO / "build" / "tools" / "bin" / "grpc-health-probe"
    print("\nbeyond one machine: a fleet (docs/scaling.md):")
    if not shutil.which("haproxy") or not probe.is_file() or not Path(server_binary).is_file():
        print(f"  skipped: needs haproxy, {probe} (make go-tools) and the server binary {server_binary}")
        return
    fleet.demo(server_binary, str(probe))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051", help="host:port of graspsim-server")
    parser.add_argument("--http", default="http://127.0.0.1:8080", help="URL of the server's HTTP/JSON gateway")
    parser.add_argument("--keep", action="store_true", help="keep the scene on the server (default: delete it)")
    parser.add_argument("--out", default=None, help="directory for the work cycle's plots (default: a temp dir)")
    parser.add_argument("--server-binary", default=str(REPO / "build" / "bin" / "graspsim-server"),
                        help="graspsim-server to start the fleet's replicas from")
    args = parser.parse_args(argv)
    try:
        with graspsim.connect(args.server) as client:
            print(f"connected to graspsim at {args.server}")
            list_models(client)
            scene_id = build_scene(client)
            open_gripper(client, scene_id)
            scene = client.get_scene(scene_id)
            print_bodies(scene)
            print_joints(scene)
            print_tactile_arrays(scene)
            print_snapshot(client, scene_id)
            read_over_http(args.http, scene_id)
            show_viewer(args.http, scene_id)
            simulate_grasp(client, scene_id)
            if not args.keep:
                client.delete_scene(scene_id)
            run_work_cycle(client, args.out)
            completed_scene = plan_grasps(client)
            hardware_gateway.demo(client, args.server)
            pick_and_place_completed(client, completed_scene)
            load_public_robot(client)
            three_engines(client)
        beyond_one_machine(args.server_binary)
    except (graspsim.GraspsimError, OSError) as err:
        print(f"demo failed: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
