#!/usr/bin/env python3
"""graspsim tactile work cycle: a PG70 on a vertical axis picks a 5 cm cube at several pad coverages.

The experiment of the OpenGRASP tactile paper (PAPERS.md, part B): the gripper approaches the cube from above,
closes under velocity control until the first tactile contact, then holds the pads' intensity sum at a set-point
(force control through the drive's current limit), lifts the cube, holds it, puts it back and lets go. It runs
once per coverage (the fraction of the pads' length the cube covers: 0.15, 0.6, 1.0 by default), each in a
fresh scene, prints a summary per run and writes PNGs: the sums against time of every run (like the paper's
Fig. 7) and each run's tactile images at the peak.

    python3 tactile_cycle.py --server 127.0.0.1:50051 --out /tmp/cycle [--figure docs/tactile-cycle.png]

Needs the "plot" extra (matplotlib) for the PNGs; without it, only the summaries are printed.
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path
from typing import Dict, Optional

import graspsim

TABLE_TOP_Z = 0.75      # m, top surface of the built-in table placed at the origin
CUBE_EDGE = 0.05        # m, built-in "cube_5cm" (0.1 kg)
GRIPPER = "cell"        # the robot id: joints "cell/z_axis", "cell/finger_left_joint"; pads "cell/pad_left" ...
CUBE = "cube"
# World height of the "schunk_pg70_on_z_axis" base (axis_base, the top of the z axis's travel; see
# server/models/schunk_pg70_on_z_axis.urdf): at z_axis = 0 the fingertips are 0.157 m below it, here 0.893 m,
# 9 cm above the cube's top. The grasp heights of coverage 0.15 .. 1.0 need z_axis -0.10 .. -0.14 m, and the
# lift 0.05 m more: all within the axis's -0.30 .. 0 m.
GRIPPER_BASE_Z = 1.05
COVERAGES = (0.15, 0.6, 1.0)
# One set-point for every coverage, so the runs compare: at coverage 0.15 the cube covers only 2 of the pads'
# 14 rows (12 texels, full scale 12 x 4095 = 49140), so the server's default of 60000 is out of reach there.
SETPOINT = 30000.0
FRAME_RATE_HZ = 200.0  # frames per simulated second: resolves the grasp's force transient (the default is 50)


def build_cell(client: graspsim.Client, name: str) -> str:
    """A fresh scene: the table, the cube resting on it, the gripper cell above the cube; returns its id."""
    scene_id = client.create_scene(name).id
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, CUBE, builtin="cube_5cm", pose=[0, 0, TABLE_TOP_Z + CUBE_EDGE / 2, 1, 0, 0, 0])
    client.add_robot(scene_id, GRIPPER, builtin="schunk_pg70_on_z_axis",
                     base_pose=[0, 0, GRIPPER_BASE_Z, 1, 0, 0, 0])
    return scene_id


def run_cycle(client: graspsim.Client, coverage: float, *, hold_time: float = 1.0,
              tactile_setpoint: float = SETPOINT, lift_height: float = 0, frame_rate_hz: float = FRAME_RATE_HZ,
              verbose: bool = True, record: Optional[str] = None) -> graspsim.WorkCycleResult:
    """Builds a fresh scene, runs the work cycle at one coverage, deletes the scene; returns the time series.
    record: a recording name ("<name>.mcap"): the run is recorded on the server, with the finger's force/torque
    (client.list_recordings() then describes it)."""
    scene_id = build_cell(client, f"tactile cycle, coverage {coverage:g}")
    stages = []

    def on_frame(frame: graspsim.WorkCycleFrame) -> None:
        if verbose and (not stages or stages[-1] != frame.stage):
            stages.append(frame.stage)
            print(f"    t = {frame.time:6.3f} s  {frame.stage:<9}  sums {frame.left.intensity_sum:6d} / "
                  f"{frame.right.intensity_sum:6d}  cube z = {frame.object_pose.position[2]:.4f} m")

    def run() -> graspsim.WorkCycleResult:
        return client.run_work_cycle(scene_id, GRIPPER, CUBE, coverage=coverage, hold_time=hold_time,
                                     tactile_setpoint=tactile_setpoint, lift_height=lift_height,
                                     frame_rate_hz=frame_rate_hz, on_frame=on_frame,
                                     progress=not verbose)  # the printed stages, or a bar: not both at once

    try:
        if record is None:
            return run()
        with client.record(scene_id, name=record, force_torque_joints=[f"{GRIPPER}/finger_left_joint"]):
            return run()
    finally:
        client.delete_scene(scene_id)


def percent(value: float) -> str:
    return "n/a" if math.isnan(value) else f"{value * 100:.2f} %"


def millimetres(value: float) -> str:
    return "n/a" if math.isnan(value) else f"{value * 1e3:+.2f} mm"


def print_summary(label: str, result: graspsim.WorkCycleResult) -> graspsim.WorkCycleSummary:
    """Prints the run's numbers: peaks, pad mismatch, rise time, lift and slip."""
    s = result.summary()
    if not len(result):
        print(f"  {label}: no frames")
        return s
    frame_period = float(result.time[1] - result.time[0]) if len(result) > 1 else 0.0
    if math.isnan(s.rise_time):
        rise = "never"
    elif s.rise_time < frame_period / 2:
        rise = f"within the contact's first frame (< {frame_period * 1e3:.0f} ms)"
    else:
        rise = f"{s.rise_time * 1e3:.0f} ms later"
    print(f"  {label}: {len(result)} frames over {result.time[-1] - result.time[0]:.2f} s, "
          f"stages {' > '.join(result.stages())}")
    print(f"    peak sums {s.peak_left:.0f} (left) / {s.peak_right:.0f} (right), mismatch {percent(s.peak_mismatch)}; "
          f"while holding at most {percent(s.hold_mismatch)} (set-point {result.tactile_setpoint:.0f})")
    print(f"    first contact at t = {s.first_contact_time:.3f} s, 90 % of the set-point {rise}")
    print(f"    cube lifted {millimetres(s.lift)} (axis {result.lift_height * 1e3:.0f} mm), "
          f"slip {millimetres(s.slip)}, put back {millimetres(s.final_offset)} from where it was")
    return s


def matplotlib_available() -> bool:
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def write_figures(results: Dict[str, graspsim.WorkCycleResult], out: Path, figure: Optional[Path] = None,
                  prefix: str = "tactile-cycle") -> list:
    """The sums of every run (Fig. 7) and each run's images at the peak, as PNGs in out; returns the paths."""
    import graspsim.plot as gplot

    out.mkdir(parents=True, exist_ok=True)
    fig = gplot.work_cycle_figure(results, title="tactile sum during the work cycle, by pad coverage")
    paths = [gplot.save(fig, out / f"{prefix}.png")]
    if figure is not None:
        figure.parent.mkdir(parents=True, exist_ok=True)
        paths.append(gplot.save(fig, figure))
    for label, result in results.items():
        tag = label.replace(" ", "").replace("coverage", "").replace("%", "pct").replace(".", "")
        peak = gplot.peak_images_figure(result, title=f"{label}: pads at the peak, "
                                                      f"t = {result.time[result.peak_index()]:.2f} s")
        paths.append(gplot.save(peak, out / f"{prefix}-peak-{tag}.png"))
    return paths


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051", help="host:port of graspsim-server")
    parser.add_argument("--out", type=Path, default=None, help="directory for the PNGs (default: a new temp dir)")
    parser.add_argument("--figure", type=Path, default=None,
                        help="also write the all-coverages figure here (e.g. docs/tactile-cycle.png)")
    parser.add_argument("--coverage", type=float, nargs="+", default=list(COVERAGES),
                        help="pad coverages to run, each in (0, 1] (default: 0.15 0.6 1.0)")
    parser.add_argument("--hold-time", type=float, default=1.0, help="s held at the top (default 1)")
    parser.add_argument("--setpoint", type=float, default=SETPOINT,
                        help=f"tactile sum per pad (default {SETPOINT:.0f}; 0 = the server's 60000)")
    parser.add_argument("--frame-rate", type=float, default=FRAME_RATE_HZ,
                        help=f"frames per simulated second (default {FRAME_RATE_HZ:g})")
    parser.add_argument("--lift", type=float, default=0, help="lift height, m (0 = the server's 0.05)")
    parser.add_argument("--quiet", action="store_true", help="no line per stage change")
    args = parser.parse_args(argv)
    results: Dict[str, graspsim.WorkCycleResult] = {}
    try:
        with graspsim.connect(args.server) as client:
            print(f"connected to graspsim at {args.server}")
            for coverage in args.coverage:
                label = f"coverage {coverage * 100:g} %"
                print(f"\nwork cycle, {label}:")
                results[label] = run_cycle(client, coverage, hold_time=args.hold_time,
                                           tactile_setpoint=args.setpoint, lift_height=args.lift,
                                           frame_rate_hz=args.frame_rate, verbose=not args.quiet)
                print_summary(label, results[label])
    except (graspsim.GraspsimError, OSError) as err:
        print(f"tactile cycle failed: {err}", file=sys.stderr)
        return 1
    if not matplotlib_available():
        print("\nmatplotlib is not installed (pip install 'graspsim[plot]'): no figures written")
        return 0
    out = args.out if args.out is not None else Path(tempfile.mkdtemp(prefix="graspsim-tactile-cycle-"))
    print("\nfigures:")
    for path in write_figures(results, out, args.figure):
        print(f"  {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
