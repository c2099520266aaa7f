#include "grasp/plan_job.h"

#include <chrono>

namespace graspsim::grasp {

StoredGraspSet StoreEntryFor(const PlanJob& job) {
  StoredGraspSet entry;
  entry.hand = job.hand;
  entry.mesh_hash = MeshHash(*job.mesh);
  const GraspSetKey key =
      MakeGraspSetKey(job.hand, entry.mesh_hash, job.obstacles, job.candidates, job.simulation, job.max_grasps);
  entry.key = key.key;
  entry.params_text = key.params_text;
  return entry;
}

std::optional<StoredGraspSet> FindOrPlan(const PlanJob& job, GraspStore* store, bool recompute,
                                         const std::function<bool(size_t, size_t)>& progress, bool* from_store) {
  StoredGraspSet entry = StoreEntryFor(job);
  *from_store = false;
  if (store && !recompute) {
    if (std::optional<StoredGraspSet> stored = store->Find(entry.key)) {
      *from_store = true;
      return stored;
    }
  }
  const GraspPlanner planner(job.hand, job.mesh, job.obstacles, job.simulation);
  std::optional<GraspSet> set = planner.Plan(planner.Candidates(job.candidates), 0, job.max_grasps, progress);
  if (!set) return std::nullopt;
  entry.created_unix = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  entry.set = std::move(*set);
  if (store) store->Put(entry);
  return entry;
}

}  // namespace graspsim::grasp
