#!/usr/bin/env python3
"""Grasp planning: a grasp set for a 5 cm cube on a table, for each built-in hand, and a picture of the best.

Builds a scene (table + cube), asks PlanGrasps for each hand (the Schunk PG70, the BarrettHand BH8-282, the
SCHUNK SDH 2.0) with bounding-box candidates, prints the counts and the best grasps (ε, contacts, pre-shape),
asks again to show the stored set coming back at once, and draws the best grasps of each hand (the cube, the
contacts with their normals, the approach of each grasp) into grasp_planning.png when matplotlib is installed.

    python3 grasp_planning.py --server 127.0.0.1:50051 [--out DIR]
"""
import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import graspsim

TABLE_TOP_Z = 0.75   # m
CUBE_EDGE = 0.05     # m
HANDS = ["schunk_pg70", "barrett_bh8_282", "schunk_sdh2"]


def build_scene(client: graspsim.Client) -> str:
    scene_id = client.create_scene("grasp planning").id
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP_Z + CUBE_EDGE / 2, 1, 0, 0, 0])
    return scene_id


def plan(client: graspsim.Client, scene_id: str, hand: str, body_id: str = "cube") -> graspsim.GraspSetResult:
    """The grasp set of body_id for hand; prints the counts and the three best grasps."""
    result = client.plan_grasps(hand, scene_id=scene_id, body_id=body_id, spacing=0.01, max_grasps=20)
    source = "stored set" if result.from_store else f"planned in {result.seconds:.2f} s " \
                                                    f"({result.candidates_per_s:,.0f} candidates/s)"
    print(f"{hand}: {result.candidates} candidates, {result.collisions} hit the table, "
          f"{result.force_closure} force closure; {source}; set {result.set_id[:12]}")
    for i, grasp in enumerate(result.grasps[:3]):
        contacts = result.contacts[result.contacts["grasp"] == i]
        links = ", ".join(sorted(set(contacts["link"])))
        print(f"  #{i + 1}: ε = {grasp['epsilon']:.4f}, volume = {grasp['volume']:.3g}, {grasp['preshape']}, "
              f"approach {np.round(grasp['approach'], 2)}, {len(contacts)} contacts on {links}")
    return result


def draw(results, out: Path) -> None:
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no picture (pip install 'graspsim[plot]')")
        return
    fig = plt.figure(figsize=(5 * len(results), 5))
    half = CUBE_EDGE / 2
    edges = [([a, b], [c, c], [d, d]) for a, b in [(-half, half)] for c in (-half, half) for d in (-half, half)]
    for k, (hand, result) in enumerate(results.items()):
        ax = fig.add_subplot(1, len(results), k + 1, projection="3d")
        for xs, ys, zs in edges:  # the cube's 12 edges
            for order in ((xs, ys, zs), (ys, zs, xs), (zs, xs, ys)):
                ax.plot(*order, color="0.5", lw=0.8)
        for i, grasp in enumerate(result.grasps[:5]):
            contacts = result.contacts[result.contacts["grasp"] == i]
            color = plt.cm.viridis(i / 5)
            ax.scatter(*contacts["point"].T, color=color, s=12)
            ax.quiver(*contacts["point"].T, *(0.01 * contacts["normal"]).T, color=color, lw=0.8)
            start = grasp["target"] - 0.06 * grasp["approach"]
            ax.quiver(*start, *(0.05 * grasp["approach"]), color=color, lw=2, arrow_length_ratio=0.2)
        ax.set_title(f"{hand}\nbest 5 of {result.force_closure} force-closure grasps")
        ax.set_xlim(-0.06, 0.06), ax.set_ylim(-0.06, 0.06), ax.set_zlim(-0.06, 0.06)
        ax.set_xlabel("x (m)"), ax.set_ylabel("y (m)"), ax.set_zlabel("z (m)")
    path = out / "grasp_planning.png"
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(path, dpi=100)
    print(f"best grasps drawn: {path}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051", help="host:port of graspsim-server")
    parser.add_argument("--out", default=None, help="directory for grasp_planning.png (default: a temp dir)")
    args = parser.parse_args(argv)
    out = Path(args.out or tempfile.mkdtemp(prefix="graspsim-grasps-"))
    out.mkdir(parents=True, exist_ok=True)
    try:
        with graspsim.connect(args.server) as client:
            scene_id = build_scene(client)
            results = {hand: plan(client, scene_id, hand) for hand in HANDS}
            start = time.perf_counter()
            again = client.plan_grasps("schunk_pg70", scene_id=scene_id, body_id="cube", spacing=0.01,
                                       max_grasps=20, progress=False)
            print(f"the same request again: from the store in {(time.perf_counter() - start) * 1e3:.1f} ms "
                  f"(from_store = {again.from_store})")
            draw(results, out)
            client.delete_scene(scene_id)
    except (graspsim.GraspsimError, OSError) as err:
        print(f"grasp planning failed: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
