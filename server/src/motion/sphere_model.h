// The conservative sphere model of an arm (VAMP's lesson: collision checking is where planning time goes, and
// spheres are the cheapest shape to test): every link's collision geometry covered by spheres fixed in the link
// frame, so "no sphere touches anything" implies "the link touches nothing".
//
// Covering rules (each sphere is the circumscribed sphere of a cell, so the cells' union is the shape):
//   box      cut into n_x × n_y × n_z cells of edge ≤ half its smallest extent (a thin box: ≤ its thickness,
//            at most 2.5 cm; at most 128 cells);
//   cylinder cut into n slices of height ≤ half its radius, each slice's sphere √(r² + (h/2)²);
//   sphere   itself;   mesh   its bounding box, as a box.
// Self-collision pairs (MoveIt's "adjacent" and "default" rules): links rigid on arm dofs fewer than three apart
// are no pair (the joint ranges keep them apart; see the .cpp), nor are links whose spheres already (nearly)
// overlap at q = 0.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "motion/arm.h"
#include "world/model.h"

namespace graspsim::motion {

struct LinkSpheres {
  std::vector<Vec3> centres;       // link frame, m
  std::vector<double> radii;       // m
  Vec3 bound_centre = Vec3::Zero();  // one sphere holding all of them (the broad phase)
  double bound_radius = -1;        // < 0: the link has no geometry
};

// The spheres covering one geometry, in the frame of the body it belongs to (geometry.origin applied).
void CoverGeometry(const Geometry& geometry, std::vector<Vec3>* centres, std::vector<double>* radii);

struct ArmSphereModel {
  std::vector<LinkSpheres> links;                    // indexed like ArmModel::links()
  std::vector<int> group;                            // per link: the arm dof it rides on (-1: the base)
  std::vector<std::pair<uint32_t, uint32_t>> self_pairs;  // link pairs that must not touch, i < j
  // Per dof: a bound on how far any point of the arm moves per radian (or metre) of that joint, m; used to
  // space the checks along a motion (collision_checker.h).
  std::vector<double> lever;
};

// `margin`: self pairs whose spheres come closer than this at q = 0 are left out (the checker inflates every
// sphere by half its resolution, so pass at least the resolution).
ArmSphereModel BuildSphereModel(const SceneModel& model, const ArmModel& arm, double margin = 0.01);

}  // namespace graspsim::motion
