#include "grasp/candidates.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace graspsim::grasp {
namespace {

// SplitMix64: a tiny generator whose sequence is fixed by its definition, so seeds reproduce everywhere.
class SplitMix {
 public:
  explicit SplitMix(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }  // [0, 1)

 private:
  uint64_t state_;
};

// An approach line before pre-shapes, standoffs and rolls are applied.
struct Approach {
  Vec3 direction, target, reference;
};

Vec3 Perpendicular(const Vec3& v, const Vec3& preferred, const Vec3& fallback) {
  Vec3 p = preferred - preferred.dot(v) * v;
  if (p.norm() < 1e-6) p = fallback - fallback.dot(v) * v;
  if (p.norm() < 1e-6) p = v.unitOrthogonal();
  return p.normalized();
}

void BoundingBoxApproaches(const GraspObject& object, const CandidateParams& params, SplitMix* random,
                           std::vector<Approach>* out) {
  const Vec3 lo = object.lo() - Vec3::Constant(params.padding), hi = object.hi() + Vec3::Constant(params.padding);
  collision::RayBatch rays;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = std::max(1, static_cast<int>(std::ceil((hi[u] - lo[u]) / params.spacing)));
    const int nv = std::max(1, static_cast<int>(std::ceil((hi[v] - lo[v]) / params.spacing)));
    for (int side = -1; side <= 1; side += 2) {
      Vec3 inward = Vec3::Zero();
      inward[axis] = -side;
      for (int i = 0; i < nu; ++i) {
        for (int j = 0; j < nv; ++j) {
          Vec3 p;
          p[axis] = side > 0 ? hi[axis] : lo[axis];
          p[u] = lo[u] + (hi[u] - lo[u]) * (i + random->Uniform()) / nu;  // one jittered sample per cell
          p[v] = lo[v] + (hi[v] - lo[v]) * (j + random->Uniform()) / nv;
          rays.Add(p, inward, hi[axis] - lo[axis], 0);
        }
      }
    }
  }
  object.bvh().Intersect(&rays);
  const Mat3& axes = object.principal_axes();
  for (size_t r = 0; r < rays.size(); ++r) {
    if (!rays.Hit(r)) continue;
    const Vec3 normal = object.face_normals()[rays.Triangle(r)];
    if (normal.isZero()) continue;
    const Vec3 hit = rays.Origin(r) + rays.T(r) * rays.Direction(r);
    const Vec3 direction = -normal;
    out->push_back({direction, hit, Perpendicular(direction, axes.col(0), axes.col(1))});
  }
}

void GraspPointApproaches(const GraspObject& object, const CandidateParams& params, std::vector<Approach>* out) {
  Vec3 a, b;
  if (params.grasp_points) {
    std::tie(a, b) = *params.grasp_points;
  } else {  // detected: where the minor axis through the centroid leaves the surface on both sides
    const Vec3 minor = object.principal_axes().col(2);
    const double far = 2 * object.characteristic_length() + 0.01;
    collision::RayBatch rays;
    rays.Add(object.centroid() + far * minor, -minor, 2 * far, 0);
    rays.Add(object.centroid() - far * minor, minor, 2 * far, 1);
    object.bvh().Intersect(&rays);
    if (!rays.Hit(0) || !rays.Hit(1)) return;
    a = object.centroid() + (far - rays.T(0)) * minor;
    b = object.centroid() - (far - rays.T(1)) * minor;
  }
  const Vec3 axis = (b - a).normalized();
  const Vec3 u = Perpendicular(axis, object.principal_axes().col(0), object.principal_axes().col(1));
  const Vec3 v = axis.cross(u);
  for (int k = 0; k < params.circle_samples; ++k) {
    const double phi = std::numbers::pi * k / params.circle_samples;
    const Vec3 direction = -(std::cos(phi) * u + std::sin(phi) * v);
    // Hand +y = z × x should run along the axis: x = axis × z.
    out->push_back({direction, 0.5 * (a + b), axis.cross(direction).normalized()});
  }
}

void CentroidCircleApproaches(const GraspObject& object, const CandidateParams& params, std::vector<Approach>* out) {
  const Mat3& axes = object.principal_axes();
  const Vec3 c = object.centroid();
  for (int circle = 0; circle < 2; ++circle) {
    const Vec3 normal = axes.col(circle);  // major, then middle eigenvector
    const Vec3 u = circle == 0 ? axes.col(1) : axes.col(0);
    const Vec3 v = normal.cross(u);
    for (int k = 0; k < params.circle_samples; ++k) {
      const double phi = 2 * std::numbers::pi * k / params.circle_samples;
      const Vec3 direction = -(std::cos(phi) * u + std::sin(phi) * v);
      // Fingers close across the circle's normal (the long axis for the first circle).
      out->push_back({direction, c, Perpendicular(direction, normal, u)});
    }
  }
}

}  // namespace

std::vector<Candidate> GenerateCandidates(const GraspObject& object, double roll_period, const CandidateParams& params) {
  SplitMix random(params.seed);
  std::vector<Approach> approaches;
  switch (params.method) {
    case CandidateMethod::kBoundingBox: BoundingBoxApproaches(object, params, &random, &approaches); break;
    case CandidateMethod::kGraspPoints: GraspPointApproaches(object, params, &approaches); break;
    case CandidateMethod::kCentroidCircles: CentroidCircleApproaches(object, params, &approaches); break;
  }
  std::vector<Candidate> out;
  out.reserve(approaches.size() * params.preshapes.size() * params.standoffs.size() * params.rolls);
  for (const Approach& a : approaches) {
    for (uint32_t preshape : params.preshapes) {
      for (double standoff : params.standoffs) {
        for (int r = 0; r < params.rolls; ++r) {
          out.push_back({a.direction, a.target, a.reference, roll_period * r / params.rolls, standoff, preshape});
        }
      }
    }
  }
  if (params.max_candidates > 0 && out.size() > params.max_candidates) {
    // Selection sampling (Knuth's algorithm S): a uniform subset that keeps the generation order.
    std::vector<Candidate> kept;
    kept.reserve(params.max_candidates);
    size_t needed = params.max_candidates;
    for (size_t i = 0; i < out.size() && needed > 0; ++i) {
      if (random.Uniform() * static_cast<double>(out.size() - i) < static_cast<double>(needed)) {
        kept.push_back(out[i]);
        --needed;
      }
    }
    out = std::move(kept);
  }
  return out;
}

std::optional<CandidateMethod> ParseCandidateMethod(const std::string& name) {
  if (name == "bounding_box") return CandidateMethod::kBoundingBox;
  if (name == "grasp_points") return CandidateMethod::kGraspPoints;
  if (name == "centroid_circles") return CandidateMethod::kCentroidCircles;
  return std::nullopt;
}

const char* CandidateMethodName(CandidateMethod method) {
  switch (method) {
    case CandidateMethod::kBoundingBox: return "bounding_box";
    case CandidateMethod::kGraspPoints: return "grasp_points";
    case CandidateMethod::kCentroidCircles: return "centroid_circles";
  }
  return "";
}

}  // namespace graspsim::grasp
