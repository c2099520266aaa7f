"""python -m graspsim.batch grasp-db --meshes DIR --hands schunk_pg70,... --out DIR [--address A] [--workers N]"""
import argparse
import json
import sys
from typing import Optional, Sequence
from pathlib import Path

from graspsim.batch._grasp_db import MESH_SUFFIXES, plan_grasp_database


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m graspsim.batch")
    commands = parser.add_subparsers(dest="command", required=True)
    db = commands.add_parser("grasp-db", help="plan the grasp sets of every mesh of a directory for every hand")
    db.add_argument("--meshes", required=True, type=Path, help="directory of STL/OBJ/PLY files (not recursive)")
    db.add_argument("--hands", required=True, help="comma-separated: schunk_pg70,barrett_bh8_282,schunk_sdh2")
    db.add_argument("--out", required=True, type=Path, help="output directory (the dataset is OUT/grasps)")
    db.add_argument("--address", help="Ray cluster to join (default: a local Ray)")
    db.add_argument("--workers", type=int, help="server actors (default: the cluster's CPUs / compute threads)")
    db.add_argument("--seed", type=int, default=1)
    db.add_argument("--params", default="{}", help='plan_grasps parameters as JSON, e.g. {"spacing": 0.01}')
    db.add_argument("--server", help="graspsim-server binary (default: $GRASPSIM_SERVER, else on the PATH)")
    db.add_argument("--compute-threads", type=int, help="each server's --compute-threads (default 1)")
    db.add_argument("--store-dir", help="keep each worker's server data dir (SQLite grasp store) under this")
    db.add_argument("--retry-errors", action="store_true", help="run again the tasks that recorded an error")
    db.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    meshes = sorted(p for p in args.meshes.iterdir() if p.suffix.lower() in MESH_SUFFIXES)
    if not meshes:
        parser.error(f"--meshes: no {'/'.join(MESH_SUFFIXES)} files in {args.meshes}")
    summary = plan_grasp_database(meshes, [h for h in args.hands.split(",") if h], out_dir=args.out,
                                  params=json.loads(args.params), workers=args.workers, seed=args.seed,
                                  progress=not args.no_progress, server=args.server, address=args.address,
                                  compute_threads=args.compute_threads, store_dir=args.store_dir,
                                  retry_errors=args.retry_errors)
    print(json.dumps(summary.as_dict()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
