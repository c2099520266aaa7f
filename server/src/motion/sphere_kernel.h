// The batched sphere test at the heart of planning (VAMP's idea, Thomason et al. 2024): forward kinematics and
// sphere-vs-obstacle tests for kLanes arm configurations at once, one configuration per SIMD lane, so that one
// instruction moves all of them. Plain data in, no Eigen, no std: the kernel is compiled twice (AVX2 + FMA and a
// portable SSE2 build, sphere_kernel_avx2.cpp / sphere_kernel_generic.cpp from sphere_kernel_impl.inc) and chosen
// once at run time by the CPU's features, so no inline function is shared between the two builds.
//
// Floats: centres are placed to ~1e-6 m at 1 m of reach; callers add kFloatMargin to every radius so the float
// test errs on the side of "touches".
#pragma once

#include <cstdint>

namespace graspsim::motion::kernel {

constexpr int kLanes = 8;
constexpr float kFloatMargin = 2e-5f;  // m, added to radii: covers the float rounding of FK and of the tests

enum JointKind : int32_t { kRigid = 0, kRevolute = 1, kPrismatic = 2 };

struct Link {
  int32_t parent = -1;          // index of an earlier link; -1: the robot's base (placed at `base`)
  int32_t dof = -1;             // row of q moving it; -1: rigid on its parent
  int32_t kind = kRigid;
  float rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // parent frame -> joint frame, row-major
  float translation[3] = {0, 0, 0};
  // rotation is a signed permutation (column j = ±e_permutation[j]; URDF offsets mostly turn by quarter turns):
  // FK then permutes the parent's columns instead of multiplying. -1: a general rotation.
  int32_t permutation[3] = {-1, -1, -1};
  int32_t same_frame_as_parent = 0;  // rigid with an identity offset (the checker folds rigid links so): FK copies
  float axis[3] = {0, 0, 1};    // unit, joint frame; a revolute joint turns about z (frames chosen so: the checker
                                // rotates each revolute link's frame to put its axis on z)
  int32_t sphere_begin = 0, sphere_end = 0;  // its spheres, [begin, end) of Model's sphere arrays
  float bound_centre[3] = {0, 0, 0};         // one sphere holding all of them (link frame); radius < 0: none
  float bound_radius = -1;
  int32_t against_obstacles = 0;  // 0: rigid on the base (its contacts with the scene are the mounting)
};

// Obstacles, world frame; bound_radius: the obstacle's bounding sphere about its centre (the cheap first test).
struct Box { float rotation_t[9]; float centre[3]; float half[3]; float bound_radius; };  // local = R^T (p - c)
struct Ball { float centre[3]; float radius; };
struct Cylinder { float rotation_t[9]; float centre[3]; float radius, half_length, bound_radius; };  // axis: local z

struct Model {
  const Link* links = nullptr;
  int32_t link_count = 0;
  float base_rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  float base_translation[3] = {0, 0, 0};
  const float* sphere_x = nullptr;  // link frame centres and radii (kFloatMargin included), per sphere
  const float* sphere_y = nullptr;
  const float* sphere_z = nullptr;
  const float* sphere_radius = nullptr;
  int32_t sphere_count = 0;
  const Box* boxes = nullptr;
  int32_t box_count = 0;
  const Ball* balls = nullptr;
  int32_t ball_count = 0;
  const Cylinder* cylinders = nullptr;
  int32_t cylinder_count = 0;
  const int32_t* self_pairs = nullptr;  // link index pairs, flattened (a0, b0, a1, b1, ...)
  int32_t self_pair_count = 0;
  // A lane's inflation applies to link l's spheres times link_inflation[l], and to the two spheres of self pair p
  // together times pair_inflation[p] (a motion check inflates by how far each link, and each pair relative to
  // each other, can move). Null: 1 per link, 2 per pair (each sphere inflated alike).
  const float* link_inflation = nullptr;
  const float* pair_inflation = nullptr;
  // Place every sphere, not only those a test reads (a caller that tests the spheres further, e.g. against
  // meshes, needs them all; see CollidingLanes).
  bool place_every_sphere = false;
  // The obstacles' broad phase (FillObstacleBounds): each obstacle's world box, so that a link first tests the
  // box around all lanes' bounding spheres against kLanes obstacles per instruction, and then, lane by lane, only
  // the obstacles that box meets. Null: every obstacle lane by lane (the same answers, more tests).
  const float* obstacle_bounds = nullptr;
};

// Floats FillObstacleBounds writes: per group of kLanes obstacles (boxes, then balls, then cylinders, in their
// order) 6 rows of kLanes, the lower then the upper x, y, z of each one's world box, grown by 0.1 mm so that float
// rounding cannot drop an obstacle a lane touches; slots past the last obstacle hold empty boxes.
inline int64_t ObstacleBoundsSize(const Model& model) {
  const int64_t obstacles = static_cast<int64_t>(model.box_count) + model.ball_count + model.cylinder_count;
  return (obstacles + kLanes - 1) / kLanes * 6 * kLanes;
}
void FillObstacleBounds(const Model& model, float* out);

// Lanes whose collision ends a CollidingLanes call at once: the answer is then decided for its caller (a
// configuration tested as it is, in a motion check), so the other lanes need not be finished.
struct StopLanes {
  uint32_t mask = 0;
};
constexpr StopLanes kRunToEnd{0};
constexpr StopLanes kStopAtFirst{(1u << kLanes) - 1};

// Floats of scratch CollidingLanes needs: every link's world transform and bounding-sphere centre, and every
// sphere's world centre, per lane; then a flag per link (its spheres placed in this call; kLanes more because the
// 4-wide build's second half addresses the scratch 4 floats on).
inline int64_t ScratchSize(const Model& model) {
  return (static_cast<int64_t>(model.link_count) * 15 + static_cast<int64_t>(model.sphere_count) * 3) * kLanes +
         model.link_count + kLanes;
}

// q: one row of kLanes floats per dof (q[d * kLanes + lane]); inflate: per lane, m added to the spheres' radii
// (scaled per link and per self pair, see Model).
// Returns the lanes (bit per lane) where some sphere touches an obstacle or a sphere of a self pair. It returns
// as soon as a lane of `stop` collides (the mask then names at least one such lane, and other lanes may be
// unfinished) or every lane does. A lane found colliding is not tested further. With Model::place_every_sphere,
// when it returns with some lane free and no `stop` lane hit, every sphere's centre is in scratch: x, y, z of
// sphere s at SphereCentres(model, scratch) + (3 s + axis) * kLanes; without it only the spheres tested are.
uint32_t CollidingLanes(const Model& model, const float* q, const float* inflate, float* scratch, StopLanes stop);

// The same tests measuring instead of answering yes or no: clearance[lane] gets the largest inflation (m, scaled per
// link and per self pair as `inflate` is above) up to cap[lane] at which the lane's configuration would still
// touch nothing, i.e. min(cap, (d - r) / scale) over spheres at distance d from an obstacle's surface or from the
// other sphere of a self pair (r: the radius, or the two radii). Negative where the configuration touches as it is;
// those lanes are the returned mask, with the same early return on `stop` as CollidingLanes (the clearances are
// then not finished, and not to be read). A cap of 0 makes a lane the plain test. A motion check covers a segment
// from fewer configurations with it (collision_checker.h). Meshes are not measured here (the checker does that).
uint32_t ClearanceLanes(const Model& model, const float* q, const float* cap, float* scratch, float* clearance,
                        StopLanes stop);

inline const float* SphereCentres(const Model& model, const float* scratch) {
  return scratch + static_cast<int64_t>(model.link_count) * 15 * kLanes;
}

// "avx2" or "sse2": the build CollidingLanes dispatches to on this CPU.
const char* KernelIsa();

// The two builds CollidingLanes dispatches to (sphere_kernel_{generic,avx2}.cpp); called directly only by tests
// that compare them. The AVX2 one needs a CPU with AVX2 and FMA.
namespace generic {
uint32_t CollidingLanes(const Model& model, const float* q, const float* inflate, float* scratch, StopLanes stop);
uint32_t ClearanceLanes(const Model& model, const float* q, const float* cap, float* scratch, float* clearance,
                        StopLanes stop);
}
#if defined(__x86_64__)
namespace avx2 {
uint32_t CollidingLanes(const Model& model, const float* q, const float* inflate, float* scratch, StopLanes stop);
uint32_t ClearanceLanes(const Model& model, const float* q, const float* cap, float* scratch, float* clearance,
                        StopLanes stop);
}
#endif

}  // namespace graspsim::motion::kernel
