"""shape: the reconstruction stage of shape completion (issue 5): screened Poisson of our own against PCL's.

Reconstruction only. Symmetry search, segmentation, outlier removal and the PerceptionService are not built yet,
so none of these figures is the issue's end-to-end time (its goal: 39k points in <= 100 ms, 2.1k in <= 10 ms,
all stages) — they time the stage the issue names as the bottleneck (PCL's Poisson: ~0.25 s at 2k points, ~2 s
at depth 7 for 39k).

graspsim_perception_bench (tests/stress/perception_bench.cpp), in process, one core: oriented points with exact
normals on a 10 cm sphere and a 10 x 7 x 5 cm box, ~2.1k and ~39k points each (the paper's sizes), depths 5 and
7; ours (server/src/perception/poisson.h) and pcl::Poisson (one thread, defaults but the depth) on the same points
in the same run. No server is started.

- ms_2k: ours, sphere, 2.1k points, depth 5 (the paper's coarse setting); ms_2k_depth7 beside it.
- ms_39k: ours, sphere, 39.4k points, depth 7 (the paper's fine setting); ms_39k_depth5 beside it.
- pcl_poisson_ms_2k, pcl_poisson_ms_39k: pcl::Poisson on the same points and depths.
- mean_dev_mm_ours, mean_dev_mm_pcl: mean two-sided deviation from the analytic surface (mm), averaged over the
  8 runs (2 shapes x 2 sizes x 2 depths); each run's figure is in runtime_vs_error.
- ms_per_stage: ours at 39.4k points, depth 7: grid + splat, solve, iso-value, marching cubes; normals_ms: the
  plane-fit normals (k = 10) of the same cloud, the stage before (not included in ms_*).
- runtime_vs_error: every run: shape, points, depth, solved_depth (the finest level solved; finer ones are
  interpolated when the samples are sparser than ~3 cells, PoissonParams::refine_limit), ms, deviation,
  triangles, closed, and PCL's.
Wall times are medians of 5 runs (PCL: of 2); the machine is shared, so load_avg_1m (before, after) goes with them.
"""
import json
import os
import subprocess

from _harness import REPO, log

BIN = REPO / "build" / "bin"
SCOPE = ("reconstruction only (oriented points with exact normals -> closed mesh); symmetry search, segmentation, "
         "outlier removal and the PerceptionService are not built yet: not the issue's end-to-end figures")
PAPER_END_TO_END_MS = {"2k": 310, "39k": 16460}   # PAPERS.md part C, whole pipeline, one 2.8 GHz i7 core


def run():
    exe = BIN / "graspsim_perception_bench"
    if not exe.exists():
        raise RuntimeError(f"{exe} not built: run 'make build' (it needs libpcl-dev)")
    load_before = round(os.getloadavg()[0], 2)
    log("graspsim_perception_bench: sphere and box, 2.1k and 39k points, depths 5 and 7, ours and pcl::Poisson")
    data = json.loads(subprocess.run([str(exe), "5"], capture_output=True, text=True, check=True).stdout)
    runs = data["runs"]

    def pick(shape, points_min, depth):
        return next(r for r in runs if r["shape"] == shape and r["depth"] == depth and
                    (r["points"] > 10000) == (points_min > 10000))
    small5, small7 = pick("sphere", 2000, 5), pick("sphere", 2000, 7)
    large5, large7 = pick("sphere", 39000, 5), pick("sphere", 39000, 7)
    mean = lambda key: round(sum(r[key] for r in runs) / len(runs), 4)  # noqa: E731
    figures = {
        "scope": SCOPE,
        "ms_2k": small5["ms"], "ms_2k_depth7": small7["ms"],
        "ms_39k": large7["ms"], "ms_39k_depth5": large5["ms"],
        "pcl_poisson_ms_2k": small5["pcl_ms"], "pcl_poisson_ms_2k_depth7": small7["pcl_ms"],
        "pcl_poisson_ms_39k": large7["pcl_ms"], "pcl_poisson_ms_39k_depth5": large5["pcl_ms"],
        "speedup_vs_pcl_2k": round(small5["pcl_ms"] / small5["ms"], 1),
        "speedup_vs_pcl_39k": round(large7["pcl_ms"] / large7["ms"], 1),
        "mean_dev_mm_ours": mean("mean_dev_mm"), "mean_dev_mm_pcl": mean("pcl_mean_dev_mm"),
        "ms_per_stage": large7["ms_per_stage"], "solver_iterations_39k": large7["solver_iterations"],
        "normals_ms_39k": large7["normals_ms"], "normals_ms_2k": small5["normals_ms"],
        "all_closed": all(r["closed"] for r in runs), "pcl_all_closed": all(r["pcl_closed"] for r in runs),
        "runtime_vs_error": [{"shape": r["shape"], "points": r["points"], "depth": r["depth"],
                              "solved_depth": r["solved_depth"], "ms": r["ms"],
                              "mean_dev_mm": r["mean_dev_mm"], "triangles": r["triangles"], "closed": r["closed"],
                              "pcl_ms": r["pcl_ms"], "pcl_mean_dev_mm": r["pcl_mean_dev_mm"],
                              "pcl_triangles": r["pcl_triangles"]} for r in runs],
        "paper_end_to_end_ms": PAPER_END_TO_END_MS,
        "load_avg_1m": [load_before, round(os.getloadavg()[0], 2)],
    }
    return figures, 0


if __name__ == "__main__":  # alone, without the dispatcher
    print(json.dumps(run()[0]))
