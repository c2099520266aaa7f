#include "motion/sphere_model.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <random>
#include <unordered_map>

namespace graspsim::motion {
namespace {

constexpr int kMaxSpheresPerBox = 128;
constexpr int kSelfPairSamples = 10000;  // MoveIt Setup Assistant's default for "never in collision"

// Cells of a box of full edge lengths `size` centred at `centre` (geometry frame) → circumscribed spheres.
void CoverBox(const Vec3& size, const Pose& origin, std::vector<Vec3>* centres, std::vector<double>* radii) {
  // Cells of half the smallest extent (a sphere then bulges past the faces by about a third of the cell edge),
  // but no finer than 2.5 cm where the box is thicker than that: a thin finger gets one layer of cells, not
  // hundreds of tiny spheres.
  double edge = std::max({0.5 * size.minCoeff(), std::min(size.minCoeff(), 0.025), 1e-4});
  Eigen::Vector3i n;
  while (true) {
    for (int a = 0; a < 3; ++a) n[a] = std::max(1, static_cast<int>(std::ceil(size[a] / edge - 1e-9)));
    if (n.prod() <= kMaxSpheresPerBox) break;
    edge *= 1.25;  // a thin plate: fewer, larger cells
  }
  const Vec3 cell = size.cwiseQuotient(n.cast<double>());
  const double radius = 0.5 * cell.norm();
  for (int i = 0; i < n.x(); ++i) {
    for (int j = 0; j < n.y(); ++j) {
      for (int k = 0; k < n.z(); ++k) {
        const Vec3 local = -0.5 * size + cell.cwiseProduct(Vec3(i + 0.5, j + 0.5, k + 0.5));
        centres->push_back(origin * local);
        radii->push_back(radius);
      }
    }
  }
}

// Whether any sphere of link a comes within `margin` of any sphere of link b, links placed by `poses`.
bool LinksTouch(const ArmSphereModel& spheres, const std::vector<Rigid>& poses, uint32_t a, uint32_t b, double margin) {
  const LinkSpheres& la = spheres.links[a];
  const LinkSpheres& lb = spheres.links[b];
  const double reach = la.bound_radius + lb.bound_radius + margin;
  if ((poses[a] * la.bound_centre - poses[b] * lb.bound_centre).squaredNorm() >= reach * reach) return false;
  for (size_t i = 0; i < la.centres.size(); ++i) {
    const Vec3 ca = poses[a] * la.centres[i];
    for (size_t j = 0; j < lb.centres.size(); ++j) {
      const double r = la.radii[i] + lb.radii[j] + margin;
      if ((ca - poses[b] * lb.centres[j]).squaredNorm() < r * r) return true;
    }
  }
  return false;
}

// What the self pairs depend on: the links' tree, joints, offsets, limits and spheres.
uint64_t GeometryKey(const ArmModel& arm, const ArmSphereModel& spheres, double margin) {
  uint64_t hash = 1469598103934665603ull;  // FNV-1a over the bytes of every number
  const auto mix = [&](const void* data, size_t size) {
    const unsigned char* bytes = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 1099511628211ull;
  };
  const auto mix_vec = [&](const Vec3& v) { mix(v.data(), 3 * sizeof(double)); };
  mix(&margin, sizeof(margin));
  for (size_t l = 0; l < arm.links().size(); ++l) {
    const ArmLink& link = arm.links()[l];
    mix(&link.parent, sizeof(link.parent));
    mix(&link.dof, sizeof(link.dof));
    mix(&link.type, sizeof(link.type));
    mix_vec(link.axis);
    mix(link.offset.rotation.data(), 9 * sizeof(double));
    mix_vec(link.offset.translation);
    for (size_t s = 0; s < spheres.links[l].centres.size(); ++s) {
      mix_vec(spheres.links[l].centres[s]);
      mix(&spheres.links[l].radii[s], sizeof(double));
    }
  }
  mix(arm.lower().data(), arm.dof() * sizeof(double));
  mix(arm.upper().data(), arm.dof() * sizeof(double));
  return hash;
}

std::vector<std::pair<uint32_t, uint32_t>> ComputeSelfPairs(const ArmModel& arm, const ArmSphereModel& spheres,
                                                            double margin) {
  const std::vector<ArmLink>& links = arm.links();
  const size_t n = links.size();
  const auto has_geometry = [&](size_t l) { return spheres.links[l].bound_radius >= 0; };
  // Candidates: links with geometry that move relative to each other (different groups), not adjacent (a link
  // and its nearest ancestor with geometry).
  std::vector<std::vector<bool>> candidate(n, std::vector<bool>(n, false));
  for (size_t a = 0; a < n; ++a) {
    for (size_t b = a + 1; b < n; ++b) candidate[a][b] = has_geometry(a) && has_geometry(b) && spheres.group[a] != spheres.group[b];
  }
  for (size_t l = 0; l < n; ++l) {
    int ancestor = links[l].parent;
    while (ancestor >= 0 && !has_geometry(ancestor)) ancestor = links[ancestor].parent;
    if (ancestor >= 0 && has_geometry(l)) candidate[std::min<size_t>(ancestor, l)][std::max<size_t>(ancestor, l)] = false;
  }
  // Never: apart in every sampled configuration; always: touching in every one (a fixed seed: the same arm always
  // gets the same pairs).
  std::vector<Rigid> poses;
  std::vector<std::vector<int>> touched(n, std::vector<int>(n, 0));
  std::mt19937_64 rng(20111);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  VecX q(arm.dof());
  for (int sample = 0; sample < kSelfPairSamples; ++sample) {
    for (size_t i = 0; i < arm.dof(); ++i) q[i] = arm.lower()[i] + unit(rng) * (arm.upper()[i] - arm.lower()[i]);
    arm.LinkTransforms(q, &poses);
    for (uint32_t a = 0; a < n; ++a) {
      for (uint32_t b = a + 1; b < n; ++b) {
        if (candidate[a][b] && LinksTouch(spheres, poses, a, b, margin)) ++touched[a][b];
      }
    }
  }
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  for (uint32_t a = 0; a < n; ++a) {
    for (uint32_t b = a + 1; b < n; ++b) {
      if (candidate[a][b] && touched[a][b] > 0 && touched[a][b] < kSelfPairSamples) pairs.emplace_back(a, b);
    }
  }
  return pairs;
}

// The sampling costs milliseconds and every plan builds a sphere model: pairs are kept per arm geometry.
std::vector<std::pair<uint32_t, uint32_t>> SelfPairs(const ArmModel& arm, const ArmSphereModel& spheres, double margin) {
  static std::mutex mutex;
  static std::unordered_map<uint64_t, std::vector<std::pair<uint32_t, uint32_t>>> cache;
  constexpr size_t kCacheEntries = 256;
  const uint64_t key = GeometryKey(arm, spheres, margin);
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (const auto found = cache.find(key); found != cache.end()) return found->second;
  }
  std::vector<std::pair<uint32_t, uint32_t>> pairs = ComputeSelfPairs(arm, spheres, margin);
  std::lock_guard<std::mutex> lock(mutex);
  if (cache.size() >= kCacheEntries) cache.clear();
  cache.emplace(key, pairs);
  return pairs;
}

}  // namespace

void CoverGeometry(const Geometry& geometry, std::vector<Vec3>* centres, std::vector<double>* radii) {
  switch (geometry.kind) {
    case Geometry::Kind::kSphere:
      centres->push_back(geometry.origin.position);
      radii->push_back(geometry.radius);
      return;
    case Geometry::Kind::kBox:
      CoverBox(geometry.box_size, geometry.origin, centres, radii);
      return;
    case Geometry::Kind::kCylinder: {
      // Slices of half the radius: each sphere 3 % wider than the cylinder.
      const int n = std::max(1, static_cast<int>(std::ceil(geometry.length / std::max(0.5 * geometry.radius, 1e-4) - 1e-9)));
      const double slice = geometry.length / n;
      const double radius = std::hypot(geometry.radius, 0.5 * slice);
      for (int i = 0; i < n; ++i) {
        centres->push_back(geometry.origin * Vec3(0, 0, -0.5 * geometry.length + (i + 0.5) * slice));
        radii->push_back(radius);
      }
      return;
    }
    case Geometry::Kind::kMesh: {
      if (!geometry.mesh || geometry.mesh->vertices.empty()) return;
      Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
      for (const auto& v : geometry.mesh->vertices) {
        lo = lo.cwiseMin(v.cast<double>());
        hi = hi.cwiseMax(v.cast<double>());
      }
      CoverBox(hi - lo, geometry.origin * Pose{0.5 * (lo + hi), Quat::Identity()}, centres, radii);
      return;
    }
  }
}

ArmSphereModel BuildSphereModel(const SceneModel& model, const ArmModel& arm, double margin) {
  const std::vector<ArmLink>& links = arm.links();
  ArmSphereModel out;
  out.links.resize(links.size());
  out.group.resize(links.size());
  for (size_t l = 0; l < links.size(); ++l) {
    LinkSpheres& spheres = out.links[l];
    for (const Geometry& geometry : model.bodies[links[l].body].collision) {
      CoverGeometry(geometry, &spheres.centres, &spheres.radii);
    }
    if (!spheres.centres.empty()) {
      Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
      for (const Vec3& c : spheres.centres) {
        lo = lo.cwiseMin(c);
        hi = hi.cwiseMax(c);
      }
      spheres.bound_centre = 0.5 * (lo + hi);
      spheres.bound_radius = 0;
      for (size_t s = 0; s < spheres.centres.size(); ++s) {
        spheres.bound_radius =
            std::max(spheres.bound_radius, (spheres.centres[s] - spheres.bound_centre).norm() + spheres.radii[s]);
      }
    }
    out.group[l] = links[l].dof >= 0 ? links[l].dof : (links[l].parent >= 0 ? out.group[links[l].parent] : -1);
  }

  out.self_pairs = SelfPairs(arm, out, margin);

  // Levers: from each dof's axis to the farthest sphere surface it carries, through the chain of offsets
  // (triangle inequality, so it holds in every configuration), per carried link.
  out.link_lever.assign(arm.dof(), std::vector<double>(links.size(), 0.0));
  for (size_t l = 0; l < links.size(); ++l) {
    if (links[l].dof < 0) continue;
    const int dof = links[l].dof;
    std::vector<double> reach(links.size(), -1);  // bound from the joint's origin to each carried link's origin
    reach[l] = 0;
    for (size_t m = l; m < links.size(); ++m) {
      if (m != l) {
        const int p = links[m].parent;
        if (p < 0 || reach[p] < 0) continue;
        double travel = 0;  // a carried prismatic joint may move its child away by its largest stroke
        if (links[m].dof >= 0 && links[m].type == JointType::kPrismatic) {
          travel = std::max(std::abs(arm.lower()[links[m].dof]), std::abs(arm.upper()[links[m].dof]));
        }
        reach[m] = reach[p] + links[m].offset.translation.norm() + travel;
      }
      double lever = links[l].type == JointType::kPrismatic ? 1.0 : 0.0;  // a slide moves what it carries 1:1
      for (size_t s = 0; s < out.links[m].centres.size() && links[l].type != JointType::kPrismatic; ++s) {
        lever = std::max(lever, reach[m] + out.links[m].centres[s].norm() + out.links[m].radii[s]);
      }
      out.link_lever[dof][m] = lever;
    }
  }
  return out;
}

}  // namespace graspsim::motion
