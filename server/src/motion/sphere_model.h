// The conservative sphere model of an arm (VAMP's lesson: collision checking is where planning time goes, and
// spheres are the cheapest shape to test): every link's collision geometry covered by spheres fixed in the link
// frame, so "no sphere touches anything" implies "the link touches nothing".
//
// Covering rules (each sphere is the circumscribed sphere of a cell, so the cells' union is the shape):
//   box      cut into n_x × n_y × n_z cells of edge ≤ half its smallest extent (a thin box: ≤ its thickness,
//            at most 2.5 cm; at most 128 cells);
//   cylinder cut into n slices of height ≤ half its radius, each slice's sphere √(r² + (h/2)²);
//   sphere   itself;   mesh   its bounding box, as a box.
// Self-collision pairs, computed as MoveIt's Setup Assistant computes an SRDF's allowed pairs: every two links with
// geometry that move relative to each other, except adjacent ones (a link and its nearest ancestor with geometry)
// and those apart by `margin` ("never") or touching ("always") in all of 10,000 seeded random configurations.
// MoveIt also rules out pairs touching at the home configuration ("default"); with spheres fatter than the meshes
// that rule removed pairs that do meet (the Panda's forearm and hand touch at q = 0 and fold together elsewhere). Cached per arm geometry (the sampling takes milliseconds).
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
  // link_lever[dof][link]: a bound on how far any point of the link moves per radian (or metre) of that joint,
  // m (0 where the dof does not move the link); it spaces and inflates the checks of a motion
  // (collision_checker.h).
  std::vector<std::vector<double>> link_lever;
};

// `margin`: a pair that comes closer than this in some sampled configuration is checked (so pairs that nearly meet
// in the samples are not ruled out by chance).
ArmSphereModel BuildSphereModel(const SceneModel& model, const ArmModel& arm, double margin = 0.0);

}  // namespace graspsim::motion
