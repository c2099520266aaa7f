#include "motion/sphere_model.h"

#include <algorithm>
#include <cmath>

namespace graspsim::motion {
namespace {

constexpr int kMaxSpheresPerBox = 128;
// Links fewer dofs apart than this are never a self pair. Two apart (upper arm and forearm across the elbow's
// two-axis housing, forearm and hand across the wrist) meet only at the ends of the joint ranges, which the
// manufacturers set so that they do not; our link shapes are rough outlines that would meet there first.
constexpr int kSelfPairDofs = 3;

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

  // Self pairs: groups at least kSelfPairDofs dofs apart whose spheres are clear of each other at q = 0 by `margin`.
  std::vector<Rigid> poses;
  arm.LinkTransforms(VecX::Zero(arm.dof()), &poses);
  for (uint32_t a = 0; a < links.size(); ++a) {
    for (uint32_t b = a + 1; b < links.size(); ++b) {
      if (out.links[a].bound_radius < 0 || out.links[b].bound_radius < 0) continue;
      if (std::abs(out.group[a] - out.group[b]) < kSelfPairDofs) continue;
      bool touching = false;
      for (size_t i = 0; i < out.links[a].centres.size() && !touching; ++i) {
        const Vec3 ca = poses[a] * out.links[a].centres[i];
        for (size_t j = 0; j < out.links[b].centres.size() && !touching; ++j) {
          const Vec3 cb = poses[b] * out.links[b].centres[j];
          touching = (ca - cb).norm() < out.links[a].radii[i] + out.links[b].radii[j] + margin;
        }
      }
      if (!touching) out.self_pairs.emplace_back(a, b);
    }
  }

  // Levers: from each dof's axis to the farthest sphere surface it carries, through the chain of offsets
  // (triangle inequality, so it holds in every configuration).
  out.lever.assign(arm.dof(), 0.0);
  for (size_t l = 0; l < links.size(); ++l) {
    if (links[l].dof < 0) continue;
    if (links[l].type == JointType::kPrismatic) {
      out.lever[links[l].dof] = 1;
      continue;
    }
    std::vector<double> reach(links.size(), -1);  // bound from the joint's origin to each carried link's origin
    reach[l] = 0;
    double lever = 0;
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
      for (size_t s = 0; s < out.links[m].centres.size(); ++s) {
        lever = std::max(lever, reach[m] + out.links[m].centres[s].norm() + out.links[m].radii[s]);
      }
    }
    out.lever[links[l].dof] = lever;
  }
  return out;
}

}  // namespace graspsim::motion
