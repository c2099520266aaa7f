// A grasp set as PlanGrasps and PickAndPlace ask for one: the planner's inputs, the store's key for them, and the
// set found in the store or planned now and stored.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "grasp/candidates.h"
#include "grasp/planner.h"
#include "grasp/store.h"

namespace graspsim::grasp {

struct PlanJob {
  std::string hand;
  std::shared_ptr<const TriangleMesh> mesh;
  std::vector<ObstacleBox> obstacles;
  CandidateParams candidates;
  ClosingParams simulation;
  size_t max_grasps = 50;
};

// The set's identity in the store (key, hand, mesh hash, parameters), without the set.
StoredGraspSet StoreEntryFor(const PlanJob& job);

// The stored set for `job` unless `recompute` (then *from_store is true), else the set planned now on two
// threads (the machines have two cores; other requests keep the pool's other threads) and stored when `store`
// is given. `progress(done, total)` returning false cancels: nullopt. `store` may be null.
std::optional<StoredGraspSet> FindOrPlan(const PlanJob& job, GraspStore* store, bool recompute,
                                         const std::function<bool(size_t, size_t)>& progress, bool* from_store);

}  // namespace graspsim::grasp
