// The kinematic closing simulation of one grasp candidate (PAPERS.md parts A and C, OpenRAVE's grasper):
//   1. place the open hand (its pre-shape) far back on the approach line, palm toward the object;
//   2. move it along the approach until the first contact;
//   3. back off by the standoff;
//   4. close each finger (its joints and the joints coupled to them) until a link touches or a joint limit;
//   5. collect the contacts (point, normal, link) and score them (quality.h).
// A candidate whose hand overlaps an obstacle box (open before closing, on its way there along the approach, or
// closed), or whose closed fingers overlap each other or the palm, is discarded (Outcome::kCollision).
//
// Sweeps are ray casts on BVHs built once: each moving surface sample of the hand casts a ray along its motion
// against the object's BVH, and each sharp vertex of the object casts the opposite ray against the link's BVH
// (in the link frame), so neither a hand corner nor an object corner can pass through the other. A revolute
// finger moves in steps short enough that a chord stays within 0.1 mm of the arc. What remains between samples
// (an object edge crossing a hand face between two samples) is bounded by half the sample spacing for edges of
// 90° or blunter: the penetration bound the tests check is contact_tolerance + sample_spacing / 2.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "collision/embree.h"
#include "core/math.h"
#include "grasp/grasp_object.h"
#include "grasp/hand_collision.h"
#include "grasp/hand_model.h"
#include "grasp/quality.h"

namespace graspsim::grasp {

struct Candidate {
  Vec3 approach = Vec3::UnitZ();   // unit, object frame: the direction the hand moves (the hand's +z)
  Vec3 target = Vec3::Zero();      // a point of the approach line, object frame, m
  Vec3 reference = Vec3::UnitX();  // unit, perpendicular to approach: the hand's +x at roll 0
  double roll = 0;                 // rad about the approach
  double standoff = 0;             // m, backed off after the first contact (0..0.2)
  uint32_t preshape = 0;           // index into the hand's pre-shapes
};

// The friction coefficient of two named materials (either order).
struct FrictionPair {
  std::string material_a, material_b;
  double friction = 0.4;  // μ, dimensionless, > 0
};

// The kinematic closing simulation's settings (not the physics engine's graspsim::SimulationParams).
struct ClosingParams {
  double friction = 0.4;            // μ, dimensionless: every material pair not in friction_pairs
  int cone_edges = 8;
  double contact_tolerance = 1e-3;  // m: surfaces closer than this touch
  double sample_spacing = 3e-3;     // m, of the hand's surface samples
  int contacts_per_link = 4;        // a link's contact patch is kept as its extreme points (the hull's corners)
  // Materials: the object's, and per hand link (by name); "" and links not listed are "default". A contact's μ
  // is its link and the object's pair in friction_pairs, else `friction`.
  std::string object_material;
  std::map<std::string, std::string> link_materials;
  std::vector<FrictionPair> friction_pairs;
};

// μ of one material pair under `params` (friction_pairs in either order, else params.friction).
double PairFriction(const ClosingParams& params, const std::string& a, const std::string& b);

enum class Outcome : uint8_t {
  kGrasp,      // simulated and scored (force closure or not)
  kMissed,     // the hand moved along the whole approach line without touching the object
  kCollision,  // the hand overlaps an obstacle (table, other body) open, approaching or closed, or itself closed
};

// Everything one simulation writes; reused between candidates (one per thread), so a warm one allocates nothing
// but qhull's own memory.
struct SimulationWork {
  collision::RayBatch rays;
  std::vector<float> ray_length;   // per ray: the chord length, m
  struct PendingRay {
    Vec3 origin, direction;        // world, unit direction
    double length;                 // the chord, m
    uint32_t sample;               // the link sample that casts it
  };
  std::vector<PendingRay> pending; // one link's rays before the two passes of a sweep
  struct LinkHit {
    uint32_t sample;
    double t, length;
    Vec3 point, normal;
  };
  std::vector<LinkHit> link_hits;  // one link's hits of both passes, put back in sample order
  std::vector<uint32_t> vertex_ids;  // sharp vertices near a link's path
  std::vector<std::pair<double, int>> link_order;  // links of a sweep, front first
  std::vector<Pose> poses, next_poses;
  std::vector<double> q;
  std::vector<GraspContact> raw, contacts;
  std::vector<double> raw_t, raw_length;  // per raw hit: distance along its chord to the surface, chord length
  std::vector<Wrench> wrenches;
  // Results.
  Pose hand_pose;                  // object frame, where the fingers closed
  std::vector<double> joints;      // joint positions at the end, per hand joint
  Quality quality;
};

class GraspSimulator {
 public:
  GraspSimulator(const HandModel& hand, const GraspObject& object, const ClosingParams& params);

  // Thread-safe; results in *work (contacts, hand_pose, joints, quality).
  Outcome Simulate(const Candidate& candidate, SimulationWork* work) const;

  // The hand's orientation for a candidate: z = approach, x = reference turned by roll.
  static Quat HandOrientation(const Candidate& candidate);

  const ClosingParams& params() const { return params_; }
  // μ of each hand link against the object (ClosingParams' materials).
  const std::vector<double>& link_friction() const { return link_friction_; }

 private:
  bool CollidesWithObstacles(const std::vector<Pose>& poses) const;
  // Sweeps `links` from work->poses to work->next_poses; raw hits into work->raw*. Returns the smallest hit
  // fraction of the move (1 = none before the end).
  double Sweep(const std::vector<int>& links, SimulationWork* work) const;
  // Moves raw hits within the contact tolerance of the stop at `fraction` into work->contacts (only those of
  // links no finger moves when `palm_only`) and clears the raw hits; `extra_gap` is added to every gap (the
  // standoff after an approach).
  void KeepContacts(double fraction, double extra_gap, bool palm_only, SimulationWork* work) const;
  void CloseFinger(size_t finger, const Pose& base, SimulationWork* work) const;
  void ReduceContacts(SimulationWork* work) const;

  const HandModel& hand_;
  const GraspObject& object_;
  const ClosingParams params_;
  std::vector<double> preshape_reach_;  // per pre-shape: farthest hand sample from the hand origin, m
  std::vector<bool> link_moves_;        // per link: moved by some finger
  std::vector<int> all_links_;
  std::vector<double> link_friction_;
  SelfCollision self_collision_;
};

}  // namespace graspsim::grasp
