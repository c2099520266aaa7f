#include "grasp/planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <atomic>

#include <time.h>

#include "core/compute_pool.h"
#include "core/error.h"
#include "core/format.h"

namespace graspsim::grasp {
namespace {

// Candidates a thread takes at a time: large enough that the shared counter is not contended, small enough
// that a cancel lands within a few milliseconds.
constexpr size_t kChunk = 64;
// qhull's whole hull costs ~10-30 ms for a grasp of 5-9 contacts: volumes for the best grasps only.
constexpr size_t kMaxVolumes = 64;
// Hand samples closer than this would make millions of rays per candidate for no gain in accuracy.
constexpr double kMinSampleSpacing = 5e-4;

double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void CheckRange(const std::string& field, double value, double lo, double hi, const char* unit) {
  if (!std::isfinite(value) || value < lo || value > hi) {
    ThrowInvalidArgument(field + ": " + FormatNumber(value) + unit + " is outside [" + FormatNumber(lo) + ", " +
                         FormatNumber(hi) + "]" + unit);
  }
}

void CheckCount(const std::string& field, int64_t value, int64_t lo, int64_t hi) {
  if (value < lo || value > hi) {
    ThrowInvalidArgument(field + ": " + std::to_string(value) + " is outside [" + std::to_string(lo) + ", " +
                         std::to_string(hi) + "]");
  }
}

}  // namespace

void ValidateClosingParams(const ClosingParams& p) {
  if (!std::isfinite(p.friction) || p.friction <= 0) {
    ThrowInvalidArgument("friction: " + FormatNumber(p.friction) + "; give a finite friction coefficient > 0");
  }
  CheckRange("friction", p.friction, 0, 10, "");
  CheckCount("cone_edges", p.cone_edges, 3, 64);
  if (!(p.contact_tolerance > 0)) {
    ThrowInvalidArgument("contact_tolerance: " + FormatNumber(p.contact_tolerance) + " m; give a tolerance > 0");
  }
  CheckRange("contact_tolerance", p.contact_tolerance, 0, 0.05, " m");
  CheckRange("sample_spacing", p.sample_spacing, kMinSampleSpacing, 0.05, " m");
  CheckCount("contacts_per_link", p.contacts_per_link, 1, 4);
  for (size_t i = 0; i < p.friction_pairs.size(); ++i) {
    const std::string field = "friction_pairs[" + std::to_string(i) + "]";
    const FrictionPair& pair = p.friction_pairs[i];
    if (!std::isfinite(pair.friction) || pair.friction <= 0) {
      ThrowInvalidArgument(field + ".friction: " + FormatNumber(pair.friction) + "; give a friction coefficient > 0");
    }
    CheckRange(field + ".friction", pair.friction, 0, 10, "");
    for (size_t j = 0; j < i; ++j) {
      ClosingParams earlier;  // μ of this pair under the earlier pair alone: > 0 when it is the same pair
      earlier.friction = -1;
      earlier.friction_pairs = {p.friction_pairs[j]};
      if (PairFriction(earlier, pair.material_a, pair.material_b) > 0) {
        ThrowInvalidArgument(field + ": the pair ('" + pair.material_a + "', '" + pair.material_b +
                             "') is also friction_pairs[" + std::to_string(j) + "]");
      }
    }
  }
}

void ValidateCandidateParams(const CandidateParams& p) {
  CheckRange("spacing", p.spacing, 1e-3, 1, " m");
  CheckRange("padding", p.padding, 0, 1, " m");
  CheckCount("circle_samples", p.circle_samples, 1, 3600);
  CheckCount("rolls", p.rolls, 1, 360);
  if (p.standoffs.empty()) ThrowInvalidArgument("standoffs: empty; give at least one standoff (m)");
  if (p.standoffs.size() > kMaxStandoffs) {
    ThrowInvalidArgument("standoffs: " + std::to_string(p.standoffs.size()) + " values; at most " +
                         std::to_string(kMaxStandoffs));
  }
  for (size_t i = 0; i < p.standoffs.size(); ++i) {
    CheckRange("standoffs[" + std::to_string(i) + "]", p.standoffs[i], 0, 0.2, " m");
  }
  if (p.preshapes.empty()) ThrowInvalidArgument("preshapes: empty; name at least one pre-shape");
  if (p.grasp_points) {
    const auto& [a, b] = *p.grasp_points;
    if (!a.allFinite() || !b.allFinite()) ThrowInvalidArgument("grasp_points: not finite");
    if ((a - b).norm() < 1e-6) {
      ThrowInvalidArgument("grasp_points: the two points are " + FormatNumber((a - b).norm()) +
                           " m apart; give two distinct points");
    }
  }
}

GraspPlanner::GraspPlanner(const std::string& hand, std::shared_ptr<const TriangleMesh> mesh,
                           std::vector<ObstacleBox> obstacles, const ClosingParams& params)
    : hand_spec_(LoadHand("hand", hand)) {
  ValidateClosingParams(params);
  hand_model_ = std::make_unique<HandModel>(hand_spec_, params.sample_spacing);
  for (const auto& entry : params.link_materials) {
    const std::string& link = entry.first;  // not a structured binding: clang 14 cannot capture one in a lambda
    const auto& links = hand_model_->links();
    if (std::none_of(links.begin(), links.end(), [&](const HandLink& l) { return l.name == link; })) {
      std::string names;
      for (const HandLink& l : links) names += (names.empty() ? "" : ", ") + l.name;
      ThrowInvalidArgument("link_materials: '" + link.substr(0, 80) + "' is not a link of " + hand_spec_.name +
                           " (" + names + ")");
    }
  }
  object_ = std::make_unique<GraspObject>(std::move(mesh), std::move(obstacles));
  simulator_ = std::make_unique<GraspSimulator>(*hand_model_, *object_, params);
}

GraspPlanner::~GraspPlanner() = default;

std::vector<Candidate> GraspPlanner::Candidates(const CandidateParams& params) const {
  ValidateCandidateParams(params);
  for (size_t i = 0; i < params.preshapes.size(); ++i) {
    if (params.preshapes[i] >= hand_model_->preshape_names().size()) {
      ThrowInvalidArgument("preshapes[" + std::to_string(i) + "]: index " + std::to_string(params.preshapes[i]) +
                           " is not a pre-shape of " + hand_spec_.name);
    }
  }
  return GenerateCandidates(*object_, hand_model_->roll_period(), params);
}

void GraspPlanner::AddVolumes(std::vector<PlannedGrasp>* grasps, size_t width) const {
  // Whole hulls are the slow part of a plan's answer (~10-100 ms each): the kept grasps are shared out.
  const size_t count = std::min(grasps->size(), kMaxVolumes);
  const ClosingParams& p = simulator_->params();
  std::atomic<size_t> next{0};
  ComputePool::Shared().Run(std::min(width, count), [&](size_t) {
    std::vector<Wrench> wrenches;
    for (size_t i = next.fetch_add(1); i < count; i = next.fetch_add(1)) {
      PlannedGrasp& grasp = (*grasps)[i];
      ContactWrenches(grasp.contacts.data(), grasp.contacts.size(), object_->centroid(),
                      object_->characteristic_length(), simulator_->link_friction(), p.cone_edges, &wrenches);
      grasp.quality.volume = HullQuality(wrenches, true).volume;
    }
  });
}

Outcome GraspPlanner::Evaluate(const Candidate& candidate, PlannedGrasp* grasp) const {
  SimulationWork work;
  const Outcome outcome = simulator_->Simulate(candidate, &work);
  grasp->candidate = candidate;
  grasp->hand_pose = work.hand_pose;
  grasp->joints = outcome == Outcome::kGrasp ? work.joints : work.q;
  grasp->contacts = work.contacts;
  grasp->quality = work.quality;
  if (outcome == Outcome::kGrasp) {
    std::vector<PlannedGrasp> one(1, *grasp);
    AddVolumes(&one, 1);
    grasp->quality.volume = one[0].quality.volume;
  }
  return outcome;
}

std::optional<GraspSet> GraspPlanner::Plan(const std::vector<Candidate>& candidates, size_t width, size_t max_grasps,
                                           const std::function<bool(size_t, size_t)>& progress) const {
  const auto start = std::chrono::steady_clock::now();
  const size_t total = candidates.size();
  ComputePool& pool = ComputePool::Shared();
  width = std::min(width == 0 ? pool.threads() : width, pool.threads());
  std::atomic<size_t> next{0}, done{0};
  std::atomic<bool> cancelled{false};
  std::vector<Outcome> outcomes(total, Outcome::kMissed);
  std::vector<std::vector<PlannedGrasp>> found(width);
  std::vector<double> cpu(width, 0.0);
  auto report_due = start;
  pool.Run(width, [&](size_t worker) {
    const double cpu0 = ThreadCpuSeconds();
    SimulationWork scratch;
    for (;;) {
      const size_t begin = next.fetch_add(kChunk);
      if (begin >= total || cancelled.load(std::memory_order_relaxed)) break;
      const size_t end = std::min(total, begin + kChunk);
      for (size_t i = begin; i < end; ++i) {
        outcomes[i] = simulator_->Simulate(candidates[i], &scratch);
        if (outcomes[i] == Outcome::kGrasp && scratch.quality.force_closure) {
          found[worker].push_back({static_cast<uint32_t>(i), candidates[i], scratch.hand_pose, scratch.joints,
                                   scratch.contacts, scratch.quality});
        }
      }
      const size_t now_done = done.fetch_add(end - begin) + (end - begin);
      // Worker 0 is the calling thread: it reports progress between its chunks, about every 20 ms.
      if (worker == 0 && now_done < total && std::chrono::steady_clock::now() >= report_due) {
        report_due = std::chrono::steady_clock::now() + std::chrono::milliseconds(20);
        if (!progress(now_done, total)) cancelled = true;
      }
    }
    cpu[worker] = ThreadCpuSeconds() - cpu0;
  });
  if (cancelled.load() || !progress(total, total)) return std::nullopt;

  GraspSet set;
  set.hand = hand_spec_.name;
  set.preshape_names = hand_model_->preshape_names();
  for (const HandLink& link : hand_model_->links()) set.link_names.push_back(link.name);
  for (const HandJoint& joint : hand_model_->joints()) set.joint_names.push_back(joint.name);
  set.candidates = total;
  for (Outcome o : outcomes) {
    set.missed += o == Outcome::kMissed;
    set.collisions += o == Outcome::kCollision;
    set.simulated += o == Outcome::kGrasp;
  }
  for (auto& list : found) {
    for (auto& g : list) set.grasps.push_back(std::move(g));
  }
  set.force_closure = set.grasps.size();
  std::sort(set.grasps.begin(), set.grasps.end(), [](const PlannedGrasp& a, const PlannedGrasp& b) {
    if (a.quality.epsilon != b.quality.epsilon) return a.quality.epsilon > b.quality.epsilon;
    return a.candidate_index < b.candidate_index;
  });
  if (max_grasps > 0 && set.grasps.size() > max_grasps) set.grasps.resize(max_grasps);
  const auto scored = std::chrono::steady_clock::now();
  set.seconds = std::chrono::duration<double>(scored - start).count();
  for (double c : cpu) set.cpu_seconds += c;
  AddVolumes(&set.grasps, width);
  set.volume_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - scored).count();
  return set;
}

}  // namespace graspsim::grasp
