#include "grasp/plan_request.h"

#include <cmath>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"

namespace graspsim::grasp {

std::vector<uint32_t> PreshapeIndices(const HandSpec& hand, const std::vector<std::string>& names,
                                      const std::string& field) {
  std::vector<uint32_t> indices;
  for (size_t i = 0; i < names.size(); ++i) {
    const Preshape& p = FindPreshape(hand, field + "[" + std::to_string(i) + "]", names[i]);
    indices.push_back(static_cast<uint32_t>(&p - hand.preshapes.data()));
  }
  if (indices.empty()) {
    for (uint32_t p = 0; p < hand.preshapes.size(); ++p) indices.push_back(p);
  }
  return indices;
}

CandidateMethod CandidateMethodNamed(const std::string& field, const std::string& name) {
  const std::string method = name.empty() ? "bounding_box" : name;
  const auto parsed = ParseCandidateMethod(method);
  if (!parsed) {
    ThrowInvalidArgument(field + ": '" + method.substr(0, 80) +
                         "' is not one of bounding_box, grasp_points, centroid_circles");
  }
  return *parsed;
}

size_t MaxGrasps(const std::string& field, uint64_t requested) {
  if (requested > kMaxGraspsLimit) {
    ThrowInvalidArgument(field + ": " + std::to_string(requested) + "; at most " + std::to_string(kMaxGraspsLimit));
  }
  return requested == 0 ? kDefaultMaxGrasps : static_cast<size_t>(requested);
}

Candidate CandidateFrom(const HandSpec& hand, const CandidateParts& parts, const std::string& field) {
  Candidate out;
  CheckFinite(field + ".approach", parts.approach);
  if (parts.approach.norm() < 1e-9) ThrowInvalidArgument(field + ".approach: zero; give a direction");
  out.approach = parts.approach.normalized();
  CheckFinite(field + ".reference", parts.reference);
  Vec3 reference = parts.reference - parts.reference.dot(out.approach) * out.approach;
  if (reference.norm() < 1e-6) reference = out.approach.unitOrthogonal();  // absent or along the approach
  out.reference = reference.normalized();
  CheckFinite(field + ".target", parts.target);
  out.target = parts.target;
  CheckFinite(field + ".roll", parts.roll);
  out.roll = parts.roll;
  if (!std::isfinite(parts.standoff) || parts.standoff < 0 || parts.standoff > 0.2) {
    ThrowInvalidArgument(field + ".standoff: " + FormatNumber(parts.standoff) + " m is outside [0, 0.2] m");
  }
  out.standoff = parts.standoff;
  const Preshape& preshape = FindPreshape(hand, field + ".preshape", parts.preshape);
  out.preshape = static_cast<uint32_t>(&preshape - hand.preshapes.data());
  return out;
}

StoredGraspSet FindStoredSet(const GraspStore* store, const std::string& field, const std::string& id) {
  if (id.size() != 64 || id.find_first_not_of("0123456789abcdef") != std::string::npos) {
    ThrowInvalidArgument(field + ": '" + id.substr(0, 80) + "' is not a grasp-set id (64 lowercase hex digits)");
  }
  if (!store) {
    throw Error(ErrorCode::kFailedPrecondition, field + ": the server stores no grasp sets (--grasp-data-dir=off)");
  }
  std::optional<StoredGraspSet> stored = store->Find(id);
  if (!stored) ThrowNotFound(field + ": no stored grasp set '" + id + "'");
  return std::move(*stored);
}

}  // namespace graspsim::grasp
