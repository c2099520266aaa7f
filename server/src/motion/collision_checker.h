// Collision checking for planning, built for speed: the arm's sphere model (sphere_model.h) against the scene's
// obstacles as exact primitives (boxes, balls, cylinders: closed-form sphere tests) and distance grids (meshes:
// collision/distance_grid.h), with a bounding sphere per link as the broad phase. Configurations are tested
// kernel::kLanes at a time by the SIMD kernel (sphere_kernel.h); meshes, rare in planning scenes, by a scalar
// pass over the lanes the kernel leaves free. No allocation per check: buffers are owned by the checker (so one
// checker per thread).
//
// A configuration is valid when no sphere touches an obstacle or a sphere of a self pair (radii as modelled, plus
// the kernel's float margin of 0.02 mm). A motion (straight joint-space segment) is checked conservatively, not
// just sampled: every point of link l moves at most T_l = Σ_i |Δq_i| · lever_il along it (sphere_model.h), so a
// point of the segment at which link l's spheres could be inflated by c T_l / T and still touch nothing (its
// clearance c, measured by the kernel: T the largest T_l) keeps the swept link free over c / T of the segment on
// either side; a self pair likewise with the motion of one link relative to the other (only the joints between
// them), so a wrist near its own forearm is not inflated by what the shoulder does. Round one measures points
// kCoarseSteps · resolution of travel apart (at least a batch of them, spread along the motion so that a motion
// into an obstacle, most of what a search tries in clutter, is refused by its first batch); each further round
// measures points in the gaps the clearances leave, as many per gap as fill a batch, until none is left. A point
// that touches ends the motion, and so does a gap below resolution / 2^kMaxHalvings ("too close to call"). So a
// motion through a passage a few millimetres wide, or ending at a goal 1 mm from a shelf, is accepted when it is
// free, at the price of more checks there only; a valid motion touches nothing anywhere on it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "collision/distance_grid.h"
#include "motion/arm.h"
#include "motion/sphere_kernel.h"
#include "motion/sphere_model.h"

namespace graspsim::motion {

// Everything the arm must not touch, world frame.
struct Obstacles {
  struct Box { Mat3 rotation; Vec3 centre; Vec3 half; uint32_t body; };
  struct Ball { Vec3 centre; double radius; uint32_t body; };
  struct Cylinder { Mat3 rotation; Vec3 centre; double radius, half_length; uint32_t body; };
  struct Grid { std::shared_ptr<const DistanceGrid> grid; Rigid world_to_mesh; uint32_t body; };
  std::vector<Box> boxes;
  std::vector<Ball> balls;
  std::vector<Cylinder> cylinders;
  std::vector<Grid> grids;
  std::vector<std::string> body_ids;  // indexed by `body` above: SceneModel body ids
};

// Every body of the scene that is not a body of `robot_id` and not in `ignore` (ids of bodies or robots), as
// placed in `state`. Meshes get a distance grid of cell `grid_cell` m.
Obstacles CollectObstacles(const SceneModel& model, const SceneState& state, const std::string& robot_id,
                           const std::vector<std::string>& ignore = {}, double grid_cell = 0.004);

class CollisionChecker {
 public:
  // `resolution`, m of travel: a motion's first points are kCoarseSteps · resolution apart, refined near
  // obstacles down to gaps of resolution / 2^kMaxHalvings.
  CollisionChecker(const ArmModel& arm, ArmSphereModel spheres, Obstacles obstacles, double resolution = 0.01);

  // Within the joint limits and no sphere touches an obstacle or a sphere of a self pair. A configuration of the
  // wrong size throws Error(kInvalidArgument) (here and in IsMotionValid, Explain).
  bool IsValid(const Eigen::Ref<const VecX>& q) const;
  // Every configuration of the straight segment a -> b, conservatively (see above); false when a or b is not valid.
  bool IsMotionValid(const Eigen::Ref<const VecX>& a, const Eigen::Ref<const VecX>& b) const;
  // Why q is not valid ("arm/link_4 touches table", "arm/joint_a2 = 3 rad is outside [-1.7, 2.4]"); "" if valid.
  std::string Explain(const Eigen::Ref<const VecX>& q) const;

  const ArmModel& arm() const { return arm_; }
  const ArmSphereModel& spheres() const { return spheres_; }
  double resolution() const { return resolution_; }
  uint64_t checks() const { return checks_; }  // configurations tested so far (each lane of a batch counts)

  static constexpr int64_t kCoarseSteps = 16;  // resolutions of travel between a motion's first-round points
  static constexpr int kMaxHalvings = 16;      // the smallest gap: the resolution halved this often
  // A point's cap, in spacings of travel to its neighbours: half of it, so that two neighbours at their caps cover
  // what lies between them, and 0.1 % more, so that they still do after the clearances' float rounding.
  static constexpr double kCoverShare = 0.5 * 1.001;

 private:
  // The kernel on lanes_ / inflate_ (filled by the caller; `count` lanes used, the rest copies of lane 0) plus
  // the scalar mesh pass; bit per lane that collides. Returns early once a lane of `stop` collides (other lanes'
  // bits may then be missing).
  uint32_t TestLanes(int count, uint32_t stop) const;
  // Lanes count.. of lanes_ / inflate_ as copies of lane 0 (a batch is always whole), the checks counted; the
  // mask of the lanes used.
  uint32_t FillLanes(int count) const;
  // The same lanes measured (kernel::ClearanceLanes with inflate_ as the caps, plus the meshes' lower bounds):
  // each lane's clearance into clearance_; bit per lane that touches as it is.
  uint32_t MeasureLanes(int count, uint32_t stop) const;
  // The segment a -> b that SetLanes places lanes on.
  void SetMotion(const Eigen::Ref<const VecX>& a, const Eigen::Ref<const VecX>& b) const;
  // Lanes 0 .. count - 1 of lanes_ at a + t[lane] (b - a) of the segment SetMotion set (the rest at t[0]).
  void SetLanes(const double* t, int count) const;
  bool WithinLimits(const Eigen::Ref<const VecX>& q) const;
  // Sets the inflation scales for the motion a -> b; returns T (m).
  double ScaleInflation(const Eigen::Ref<const VecX>& a, const Eigen::Ref<const VecX>& b) const;
  // The scalar test (Explain): the first touching pair at the configuration whose transforms are in poses_:
  // obstacle body index or -(link + 1) for a self pair; `link` gets the arm link. False when nothing touches.
  bool FindContact(uint32_t* link, int64_t* other) const;
  void PlaceSpheres(const Eigen::Ref<const VecX>& q) const;

  const ArmModel& arm_;
  ArmSphereModel spheres_;
  Obstacles obstacles_;
  double resolution_;
  // The kernel's model and the arrays it points into.
  std::vector<kernel::Link> kernel_links_;
  std::vector<float> sphere_x_, sphere_y_, sphere_z_, sphere_radius_;
  std::vector<kernel::Box> kernel_boxes_;
  std::vector<kernel::Ball> kernel_balls_;
  std::vector<kernel::Cylinder> kernel_cylinders_;
  std::vector<float> obstacle_bounds_;  // kernel::FillObstacleBounds
  std::vector<int32_t> kernel_self_pairs_;
  kernel::Model kernel_;
  mutable std::vector<float> lanes_;    // dof rows of kLanes
  mutable float inflate_[kernel::kLanes];
  mutable std::vector<float> scratch_;
  // Inflation scales (kernel::Model): per link T_l / T and per self pair T_ab / T for the motion being checked,
  // T_l the bound on how far link l moves, T_ab on how far b moves relative to a, T the largest T_l.
  mutable std::vector<float> link_inflation_, pair_inflation_;
  // Per link and dof the link's travel due to the dofs up to that one (ScaleInflation, [link * dof + d]); per
  // dof |b - a|.
  mutable std::vector<double> travel_prefix_, joint_step_;
  mutable std::vector<double> motion_from_, motion_delta_;  // SetMotion's segment
  std::vector<double> levers_;  // spheres_.link_lever by link: levers_[link * dof + d]
  struct PairMotion { int descendant = -1; int first_dof = 0, last_dof = -1; };  // dofs moving b relative to a
  std::vector<PairMotion> pair_motion_;
  // IsMotionValid's buffers: the points measured so far in order of t, their clearance (m of the largest link's
  // travel); the points to measure this round with their caps; the gaps the last round left.
  struct Sample { double t; float clearance; };
  struct Pending { uint32_t sample; float cap; };
  struct Gap { size_t after; double from, to; };
  mutable std::vector<Sample> samples_, next_samples_;
  mutable std::vector<Pending> pending_;
  mutable std::vector<Gap> gaps_;
  mutable std::vector<uint32_t> order_;  // this round's points in the order batched
  mutable float clearance_[kernel::kLanes];
  // The scalar test's buffers.
  std::vector<uint32_t> sphere_begin_;           // per link: first sphere in the flat arrays (size links + 1)
  std::vector<double> radii_;                    // as the kernel's (float margin included)
  mutable std::vector<Rigid> poses_;
  mutable std::vector<Vec3> centres_;            // world
  mutable uint64_t checks_ = 0;
};

}  // namespace graspsim::motion
