// Force-closure quality of a grasp (Ferrari & Canny 1992, as in GraspIt! and OpenRAVE; PAPERS.md part A).
//
// Each contact i (point p_i, unit normal n_i pointing into the object) is a point contact with Coulomb
// friction μ. Its friction cone is linearised by m edges (default 8)
//   f_ik = n_i + μ (cos θ_k t1_i + sin θ_k t2_i),  θ_k = 2πk/m,
// with a unit normal component (t1, t2: a fixed orthonormal tangent basis of n_i). Each edge gives a primitive
// wrench w_ik = (f_ik, (p_i − c) × f_ik / λ) ∈ R^6, c the object's centroid and λ its characteristic length,
// so that forces (N) and torques (N m / m) are comparable and the quality does not depend on the unit of length.
// The grasp wrench space is the convex hull W of all w_ik (the "L1" space: total normal force at most 1).
//   force closure  ⇔  the origin lies strictly inside W
//   ε              =  distance from the origin to the nearest facet of W (0 without force closure)
//   volume         =  the 6-D volume of W (computed by qhull for the grasps a plan returns)
// Two frictionless contacts can never be force closure; neither can two frictional point contacts (nothing
// resists torsion about the line through them), which is why the PG70's flat jaws report several contacts each.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "core/math.h"

namespace graspsim::grasp {

struct GraspContact {
  Vec3 point = Vec3::Zero();   // m, object frame
  Vec3 normal = Vec3::UnitZ(); // unit, object frame, into the object (the direction the hand pushes)
  int link = -1;               // hand link index
};

struct Quality {
  double epsilon = 0;  // dimensionless
  double volume = 0;   // dimensionless (6-D)
  bool force_closure = false;
};

using Wrench = std::array<double, 6>;

// The primitive wrenches of `count` contacts, appended to *wrenches (cleared first). friction >= 0; friction 0
// gives one wrench per contact (the normal).
void ContactWrenches(const GraspContact* contacts, size_t count, const Vec3& centroid, double length,
                     double friction, int cone_edges, std::vector<Wrench>* wrenches);

// The same with μ per hand link: contact i has μ = link_friction[contacts[i].link] (> 0).
void ContactWrenches(const GraspContact* contacts, size_t count, const Vec3& centroid, double length,
                     const std::vector<double>& link_friction, int cone_edges, std::vector<Wrench>* wrenches);

// ε, volume and force closure of the convex hull of `wrenches` (qhull, the whole hull). Degenerate sets (fewer
// than 7 points, or not spanning R^6) are not force closure: ε = volume = 0. `joggle` (qhull's QJ: the input
// moved by ~1e-11 relative, with qhull's fixed seed, so repeatable) builds a simplicial hull without facet
// merging, about twice as fast on the many coplanar wrenches of flat contact patches: for volumes.
Quality HullQuality(const std::vector<Wrench>& wrenches, bool joggle = false);

// ε and force closure only, from the hull's facet nearest the origin (nearest_facet.h; qhull when that does not
// converge): the same ε as HullQuality to rounding, at a fraction of the cost. volume = -1 (not computed).
Quality FastQuality(const std::vector<Wrench>& wrenches);

// ContactWrenches, then FastQuality.
Quality GraspQuality(const GraspContact* contacts, size_t count, const Vec3& centroid, double length,
                     double friction, int cone_edges, std::vector<Wrench>* scratch);
Quality GraspQuality(const GraspContact* contacts, size_t count, const Vec3& centroid, double length,
                     const std::vector<double>& link_friction, int cone_edges, std::vector<Wrench>* scratch);

}  // namespace graspsim::grasp
