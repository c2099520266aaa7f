// Private to grasp/: a hand ready for the closing simulation, built once per planner: its kinematic tree in
// arrays, surface samples and one Embree BVH per link (in the link frame, reused for every candidate), the
// links' boxes for the obstacle test, and each finger's joint motion as a function of one closing parameter.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "collision/embree.h"
#include "grasp/hand.h"

namespace graspsim::grasp {

// An oriented box in a link's frame, m: centre, rotation (columns = box axes), half extents.
struct LinkBox {
  Vec3 centre = Vec3::Zero();
  Mat3 axes = Mat3::Identity();
  Vec3 half = Vec3::Zero();
};

// Consecutive samples sharing one normal (a box face): a translation's leading test is then one per run.
struct SampleRun {
  uint32_t begin = 0, end = 0;
  Vec3 normal = Vec3::UnitZ();
  Vec3 centre = Vec3::Zero();  // a ball around the run's samples, link frame: whole runs are culled by it
  double radius = 0;
};

struct HandLink {
  std::string name;
  int parent_joint = -1;          // the joint whose child this link is; -1 for the root
  std::vector<Vec3> samples;      // surface points, link frame, m (spacing <= the sample spacing)
  std::vector<Vec3> normals;      // outward unit normals of the samples
  std::vector<SampleRun> runs;    // the samples in runs of one normal, in order
  std::vector<LinkBox> boxes;     // bounding boxes of the collision geometries, link frame
  std::unique_ptr<collision::EmbreeScene> bvh;  // the link's surface, link frame; null for a link without geometry
  std::vector<Vec3> face_normals; // outward unit normals of the BVH's triangles, link frame
  double reach = 0;               // largest distance of a sample from the link origin, m
};

struct HandJoint {
  std::string name;
  JointType type = JointType::kFixed;
  int parent_link = 0, child_link = 0;
  Pose origin;
  Vec3 axis = Vec3::UnitZ();
  double lower = 0, upper = 0;
  int leader = -1;  // a mimic joint: its leader's index (q = multiplier q_leader + offset)
  double multiplier = 1, offset = 0;
};

// A finger's motion: q_j(s) = q_j(0) + rate_j s for its joints (driven joints and the mimic joints that follow
// them), s in [0, s_max] where the first joint reaches its limit.
struct HandFinger {
  std::string name;
  std::vector<std::pair<int, double>> joint_rates;  // (joint index, dq/ds)
  std::vector<int> links;                           // links that move when s changes
  double max_step = 0;  // largest step of s for which a straight chord stays within 0.1 mm of any sample's arc
  bool straight = false;  // prismatic joints only: the whole closing is one straight stroke
};

class HandModel {
 public:
  // Samples every link surface at `sample_spacing` (m).
  HandModel(const HandSpec& spec, double sample_spacing);

  const std::string& name() const { return name_; }
  const std::vector<HandLink>& links() const { return links_; }
  const std::vector<HandJoint>& joints() const { return joints_; }
  const std::vector<HandFinger>& fingers() const { return fingers_; }
  const std::vector<std::string>& preshape_names() const { return preshape_names_; }
  double roll_period() const { return roll_period_; }

  // Joint positions of pre-shape `index` (every joint; fixed joints 0).
  const std::vector<double>& PreshapeJoints(size_t index) const { return preshapes_[index]; }
  // The largest s finger `f` can close from joint positions q before a joint reaches its limit.
  double ClosingRange(size_t f, const std::vector<double>& q) const;
  // Link poses for hand pose `base` and joint positions q, into *poses (sized to the links; no allocation).
  void LinkPoses(const Pose& base, const std::vector<double>& q, std::vector<Pose>* poses) const;

 private:
  std::string name_;
  std::vector<HandLink> links_;
  std::vector<HandJoint> joints_;  // topological order
  std::vector<HandFinger> fingers_;
  std::vector<std::vector<double>> preshapes_;
  std::vector<std::string> preshape_names_;
  double roll_period_ = 0;
};

}  // namespace graspsim::grasp
