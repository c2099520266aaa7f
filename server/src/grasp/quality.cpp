#include "grasp/quality.h"

#include "grasp/nearest_facet.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <Eigen/Eigenvalues>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace graspsim::grasp {
namespace {

// Relative size of the smallest principal extent of the wrench cloud below which it does not span R^6: qhull
// would stop on a flat initial simplex, and a hull that thin has ε ~ 0 anyway.
constexpr double kFlatRatio = 1e-9;

// qhull writes its diagnostics to a stream; a degenerate grasp is an expected outcome, not an error to print.
FILE* QuietStream() {
  static FILE* sink = std::fopen("/dev/null", "w");
  return sink != nullptr ? sink : stderr;
}

void TangentBasis(const Vec3& n, Vec3* t1, Vec3* t2) {
  // The axis least aligned with n, so the cross product is well conditioned; fixed, so results repeat.
  const Vec3 a = std::abs(n.x()) <= std::abs(n.y()) && std::abs(n.x()) <= std::abs(n.z()) ? Vec3::UnitX()
                 : std::abs(n.y()) <= std::abs(n.z())                                    ? Vec3::UnitY()
                                                                                         : Vec3::UnitZ();
  *t1 = n.cross(a).normalized();
  *t2 = n.cross(*t1);
}

bool SpansR6(const std::vector<Wrench>& wrenches) {
  Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
  for (const Wrench& w : wrenches) mean += Eigen::Map<const Eigen::Matrix<double, 6, 1>>(w.data());
  mean /= static_cast<double>(wrenches.size());
  Eigen::Matrix<double, 6, 6> scatter = Eigen::Matrix<double, 6, 6>::Zero();
  for (const Wrench& w : wrenches) {
    const Eigen::Matrix<double, 6, 1> d = Eigen::Map<const Eigen::Matrix<double, 6, 1>>(w.data()) - mean;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> solver(scatter, Eigen::EigenvaluesOnly);
  const auto& values = solver.eigenvalues();  // ascending
  return values(5) > 0 && values(0) > kFlatRatio * kFlatRatio * values(5);
}


void AppendContactWrenches(const GraspContact& c, const Vec3& centroid, double length, double friction,
                           int cone_edges, std::vector<Wrench>* wrenches) {
  const int edges = friction > 0 ? cone_edges : 1;
  Vec3 t1, t2;
  TangentBasis(c.normal, &t1, &t2);
  const Vec3 arm = (c.point - centroid) / length;
  for (int k = 0; k < edges; ++k) {
    const double theta = 2 * std::numbers::pi * k / edges;
    const Vec3 f = friction > 0 ? Vec3(c.normal + friction * (std::cos(theta) * t1 + std::sin(theta) * t2)) : c.normal;
    const Vec3 tau = arm.cross(f);
    wrenches->push_back({f.x(), f.y(), f.z(), tau.x(), tau.y(), tau.z()});
  }
}

}  // namespace

void ContactWrenches(const GraspContact* contacts, size_t count, const Vec3& centroid, double length,
                     double friction, int cone_edges, std::vector<Wrench>* wrenches) {
  wrenches->clear();
  for (size_t i = 0; i < count; ++i) AppendContactWrenches(contacts[i], centroid, length, friction, cone_edges, wrenches);
}

void ContactWrenches(const GraspContact* contacts, size_t count, const Vec3& centroid, double length,
                     const std::vector<double>& link_friction, int cone_edges, std::vector<Wrench>* wrenches) {
  wrenches->clear();
  for (size_t i = 0; i < count; ++i) {
    AppendContactWrenches(contacts[i], centroid, length, link_friction[contacts[i].link], cone_edges, wrenches);
  }
}

Quality HullQuality(const std::vector<Wrench>& wrenches, bool joggle) {
  Quality quality;
  if (wrenches.size() < 7 || !SpansR6(wrenches)) return quality;
  std::vector<coordT> points(6 * wrenches.size());
  for (size_t i = 0; i < wrenches.size(); ++i) {
    for (int k = 0; k < 6; ++k) points[6 * i + k] = wrenches[i][k];
  }
  qhT qh_storage;
  qhT* qh = &qh_storage;
  FILE* quiet = QuietStream();
  qh_zero(qh, quiet);
  // Default options (Qx merging in 6-D): merged facets keep exact hyperplanes through their vertices.
  char exact[] = "qhull", joggled[] = "qhull QJ";
  char* options = joggle ? joggled : exact;
  const int exit_code = qh_new_qhull(qh, 6, static_cast<int>(wrenches.size()), points.data(), False, options,
                                     nullptr, quiet);
  if (exit_code == 0) {
    double nearest = std::numeric_limits<double>::infinity();
    facetT* facet;
    FORALLfacets {
      // Outward normal, offset: points x of the hull satisfy normal·x + offset <= 0; the origin's distance to
      // the facet's plane is -offset, and negative means the origin is outside.
      nearest = std::min(nearest, -facet->offset);
    }
    if (nearest > 0 && std::isfinite(nearest)) {
      quality.epsilon = nearest;
      quality.force_closure = true;
    }
    qh_getarea(qh, qh->facet_list);
    quality.volume = qh->totvol;
  }
  qh_freeqhull(qh, !qh_ALL);
  int still_long = 0, total_long = 0;
  qh_memfreeshort(qh, &still_long, &total_long);
  return quality;
}

Quality FastQuality(const std::vector<Wrench>& wrenches) {
  Quality quality;
  quality.volume = -1;  // not computed
  if (wrenches.size() < 7) return quality;
  // The forces alone can rule force closure out: if every force has a positive component along their sum, no
  // positive combination of the wrenches has zero force, so the origin is outside W. One pass instead of a hull
  // search, for the many candidates that touch from one side only.
  Vec3 sum = Vec3::Zero();
  for (const Wrench& w : wrenches) sum += Vec3(w[0], w[1], w[2]);
  bool one_sided = true;
  for (const Wrench& w : wrenches) one_sided = one_sided && Vec3(w[0], w[1], w[2]).dot(sum) > 0;
  if (one_sided) return quality;
  const NearestFacetResult nearest = NearestFacet(wrenches);
  if (nearest.degenerate) return quality;
  if (!nearest.converged) {  // degenerate or stuck: qhull decides (and then the volume is known)
    return HullQuality(wrenches);
  }
  if (nearest.distance > 0) {
    quality.epsilon = nearest.distance;
    quality.force_closure = true;
  }
  return quality;
}

Quality GraspQuality(const GraspContact* contacts, size_t count, const Vec3& centroid, double length,
                     double friction, int cone_edges, std::vector<Wrench>* scratch) {
  ContactWrenches(contacts, count, centroid, length, friction, cone_edges, scratch);
  return FastQuality(*scratch);
}

Quality GraspQuality(const GraspContact* contacts, size_t count, const Vec3& centroid, double length,
                     const std::vector<double>& link_friction, int cone_edges, std::vector<Wrench>* scratch) {
  ContactWrenches(contacts, count, centroid, length, link_friction, cone_edges, scratch);
  return FastQuality(*scratch);
}

}  // namespace graspsim::grasp
