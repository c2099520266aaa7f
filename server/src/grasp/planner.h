// Grasp planning, the public face of grasp/: a GraspPlanner holds one hand and one object (BVHs built once)
// and simulates candidates on a few threads. Inputs are validated here, at the library's boundary, with
// messages naming the request field and the value; inside, they are trusted.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "grasp/candidates.h"
#include "grasp/grasp_object.h"
#include "grasp/hand_model.h"
#include "grasp/quality.h"
#include "grasp/simulate.h"

namespace graspsim::grasp {

struct PlannedGrasp {
  uint32_t candidate_index = 0;  // in the generated candidate list
  Candidate candidate;
  Pose hand_pose;                // object frame, where the fingers closed
  std::vector<double> joints;    // per hand joint (HandModel::joints order), rad or m
  std::vector<GraspContact> contacts;
  Quality quality;
};

struct GraspSet {
  std::string hand;
  std::vector<std::string> preshape_names, link_names, joint_names;
  uint64_t candidates = 0, missed = 0, collisions = 0, simulated = 0, force_closure = 0;
  double seconds = 0;               // wall time of simulating and scoring every candidate, s
  double cpu_seconds = 0;           // CPU time of the threads over the same work, s (per core: candidates / it)
  double volume_seconds = 0;        // wall time of the qhull volumes of the kept grasps, s
  std::vector<PlannedGrasp> grasps; // the best force-closure grasps, best ε first (ties: candidate order)
};

// Throws Error(kInvalidArgument) naming the field: friction must be finite and > 0, cone_edges 3..64,
// contact_tolerance and sample_spacing in (0, 0.05] m, contacts_per_link 1..4.
void ValidateClosingParams(const ClosingParams& params);
// spacing in [1 mm, 1 m], padding in [0, 1 m], circle_samples 1..3600, rolls 1..360, standoffs each in [0, 0.2] m
// (at least one, at most kMaxStandoffs), pre-shapes at least one, grasp points finite and distinct.
constexpr size_t kMaxStandoffs = 64;
void ValidateCandidateParams(const CandidateParams& params);

class GraspPlanner {
 public:
  // `hand`: one of HandNames() (else kInvalidArgument naming "hand"). `mesh`: validated by the caller;
  // obstacles in the object frame.
  GraspPlanner(const std::string& hand, std::shared_ptr<const TriangleMesh> mesh, std::vector<ObstacleBox> obstacles,
               const ClosingParams& params);
  ~GraspPlanner();

  const HandModel& hand() const { return *hand_model_; }
  const HandSpec& hand_spec() const { return hand_spec_; }
  const GraspObject& object() const { return *object_; }

  std::vector<Candidate> Candidates(const CandidateParams& params) const;

  // Simulates and scores every candidate on up to `width` threads of the shared ComputePool (0 = all of them),
  // keeps the best `max_grasps` force-closure grasps (0 = all) and computes the hull volumes of the best 64 with
  // qhull (the others keep volume -1). `progress(done, total)` is called from the calling thread about every
  // 20 ms and at the end; returning false cancels: the threads stop after their current chunk and Plan returns
  // nullopt.
  std::optional<GraspSet> Plan(const std::vector<Candidate>& candidates, size_t width, size_t max_grasps,
                               const std::function<bool(size_t, size_t)>& progress) const;

  // One candidate, simulated and scored (whatever its outcome), with its hull volume.
  Outcome Evaluate(const Candidate& candidate, PlannedGrasp* grasp) const;

 private:
  void AddVolumes(std::vector<PlannedGrasp>* grasps, size_t width) const;

  HandSpec hand_spec_;
  std::unique_ptr<HandModel> hand_model_;
  std::unique_ptr<GraspObject> object_;
  std::unique_ptr<GraspSimulator> simulator_;
};

}  // namespace graspsim::grasp
