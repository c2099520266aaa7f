// ContactFinder: body pairs culled by world boxes, then every surface sample of one body tested against the
// other body's geometries (exact distance for primitives, Embree for meshes). See contact_finder.h.
#include "collision/contact_finder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>

#include "collision/mesh_query.h"
#include "collision/primitive_sdf.h"
#include "collision/samples.h"
#include "core/error.h"

namespace graspsim {
namespace {

using collision::Aabb;

// One collision geometry of a body, in the form the inner loop wants.
struct Shape {
  Geometry::Kind kind = Geometry::Kind::kBox;
  Vec3 half = Vec3::Zero();    // box: half edge lengths
  double radius = 0;           // sphere, cylinder
  double half_length = 0;      // cylinder
  Aabb cull;                   // geometry frame bounds grown by the margin: outside it nothing can be reported
  Mat3 rotation = Mat3::Identity();  // geometry frame in the body frame
  Vec3 position = Vec3::Zero();
  const collision::MeshBvh* mesh = nullptr;
  uint32_t index = 0;  // in the body's collision list (the geometry index of its samples' features)
};

// Curved surfaces against primitives touch in points found exactly, not by samples. Samples would make a rolling
// sphere or cylinder a polyhedron on a bed of nails: its contact hops from sample to sample, and the patch of
// points around the true contact slips and is damped unevenly, which brakes rolling (11 % at 20°, issue 21).
// - A sphere against a primitive (box, sphere, cylinder): one support contact at its deepest point, instead of
//   the samples of either side.
// - A cylinder against a box: its line nearest the box, clipped to the box's face, at both ends (two points on its
//   side; one on a cap's rim when tilted), instead of its side and rim samples and of the box's samples inside
//   it; its caps' inner samples still carry it when it rests on a rim. Within 5° of standing on the face it keeps
//   every sample (the cap rests flat, on the rim's ring too).
enum class Support { kNone, kAll, kRim };
bool IsPrimitive(Geometry::Kind kind) { return kind != Geometry::Kind::kMesh; }
Support SupportOf(Geometry::Kind sampled, Geometry::Kind target) {
  using K = Geometry::Kind;
  if ((sampled == K::kSphere && IsPrimitive(target)) || (target == K::kSphere && IsPrimitive(sampled))) {
    return Support::kAll;
  }
  if (sampled == K::kBox && target == K::kCylinder) return Support::kAll;
  return sampled == K::kCylinder && target == K::kBox ? Support::kRim : Support::kNone;
}
// Within this angle of standing on a box face, a cylinder keeps its samples (all of them, and the box's inside it):
// its cap rests flat, on the rim's ring too. Beyond it, it touches along a line or on a rim point.
const double kStandingCos = std::cos(5 * std::numbers::pi / 180);

// Whether a cylinder (axis and centre in a box's frame) stands on the box face nearest its centre.
bool StandsOn(const Vec3& half, const Vec3& centre, const Vec3& axis) {
  Vec3 face;
  collision::BoxDepth(half, centre, &face);
  return std::abs(axis.dot(face)) > kStandingCos;
}

// A box's sample presses into another box along the normal of a face that faces it: the nearest face alone would
// turn a floor sample that has just slid under a block's leading edge (less deep behind that side face than under
// the bottom) into a push against the motion, its damping driven by the full sliding speed: a catch that came more
// often the smaller the step (issue 21: 13 % off the sliding acceleration at 0.25 ms). A face of the target
// qualifies when its normal opposes the normal of one of the faces the sample lies on by more than 80°. The depth
// stays the distance to the nearest face (collision::BoxDepthThrough), so a sample on the rim of two aligned
// faces (a box on a box) touches with zero force, and its force grows smoothly as it moves inside.
const double kFacingCos = std::cos(80 * std::numbers::pi / 180);

// Per face of the own box (bit order of collision::BoxDepthThrough): the target box faces that oppose it, as a
// mask. `rotation` maps the own body's frame into the target geometry's frame.
std::array<uint8_t, 6> FacingFaces(const Shape& own, const Mat3& rotation) {
  std::array<uint8_t, 6> masks{};
  const Mat3 axes = rotation * own.rotation;  // own geometry axes in the target frame, as columns
  for (int face = 0; face < 6; ++face) {
    const Vec3 n = (face & 1 ? 1.0 : -1.0) * axes.col(face / 2);
    for (int target = 0; target < 6; ++target) {
      if ((target & 1 ? 1.0 : -1.0) * n[target / 2] < -kFacingCos) masks[face] |= uint8_t(1u << target);
    }
  }
  return masks;
}

// The faces of a box that a sample (body frame) lies on, as a mask: one for a face sample, two or three on
// edges and corners.
unsigned FacesOf(const Shape& box, const Vec3& sample) {
  const Vec3 p = box.rotation.transpose() * (sample - box.position);
  const double tolerance = 1e-9 + 1e-7 * box.half.maxCoeff();
  unsigned faces = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (p[axis] >= box.half[axis] - tolerance) faces |= 1u << (2 * axis + 1);
    if (p[axis] <= -box.half[axis] + tolerance) faces |= 1u << (2 * axis);
  }
  return faces;
}

// The target faces a sample on `own_faces` may press through.
unsigned Through(const std::array<uint8_t, 6>& facing, unsigned own_faces) {
  unsigned allowed = 0;
  for (int face = 0; face < 6; ++face) {
    if (own_faces >> face & 1) allowed |= facing[face];
  }
  return allowed;
}

// The feature of a support contact: above every sample index of the sphere geometry, one per target geometry.
constexpr uint32_t kSupportFeature = 0xffff0000u;

// Penetration depth (> 0 inside) of point p (the shape's frame) into a primitive shape, and its outward normal.
double PrimitiveDepth(const Shape& shape, const Vec3& p, Vec3* normal) {
  switch (shape.kind) {
    case Geometry::Kind::kBox:
      return collision::BoxDepth(shape.half, p, normal);
    case Geometry::Kind::kSphere:
      return collision::SphereDepth(shape.radius, p, normal);
    case Geometry::Kind::kCylinder:
      return collision::CylinderDepth(shape.radius, shape.half_length, p, normal);
    case Geometry::Kind::kMesh:
      break;
  }
  return -std::numeric_limits<double>::infinity();
}

struct WorldFrame {
  Mat3 rotation;
  Vec3 position;
  Aabb bounds;  // world box of the body's geometries grown by the margin
};

// Maps a point of the sampled body's frame into one geometry frame of the other body: p_g = rotation p + translation.
struct LocalFrame {
  Mat3 rotation;
  Vec3 translation;
  Mat3 world_rotation;  // geometry frame in the world, for the normal
  Aabb cull_in_sampled;  // the target's cull box seen from the sampled body's frame (SamplesInto)
};

Aabb Grown(const Aabb& box, double margin) { return {box.lo.array() - margin, box.hi.array() + margin}; }

// Find's working buffers. A finder is shared by every simulation of its model (one per thread at a time), and a
// work cycle calls Find every step: per-thread buffers keep it free of allocations without a lock.
struct FindBuffers {
  std::vector<WorldFrame> world;
  std::vector<LocalFrame> locals;
  std::vector<uint32_t> near;
  std::vector<Support> supported;
  std::vector<std::array<uint8_t, 6>> facing;
};
FindBuffers& ThreadFindBuffers() {
  thread_local FindBuffers buffers;
  return buffers;
}

}  // namespace

struct ContactFinder::Impl {
  // What pair selection needs from the model, copied so that nothing here points into it.
  struct BodyInfo {
    bool is_static = false;
    std::string robot_id;
  };
  std::vector<BodyInfo> bodies;
  ContactFinderOptions options;
  std::map<const TriangleMesh*, std::unique_ptr<collision::MeshBvh>> meshes;  // one BVH per distinct mesh
  std::vector<collision::BodySamples> samples;  // per body
  std::vector<std::vector<Shape>> shapes;       // per body
  std::vector<std::vector<Geometry::Kind>> geometry_kinds;  // per body, per collision geometry
  std::vector<Aabb> body_bounds;                // per body, body frame, union of its geometries' boxes
  size_t max_shapes = 0;

  explicit Impl(const ContactFinderOptions& o) : options(o) {}

  // Static bodies never move each other; links of one robot are kept apart by its joints, not by contacts.
  bool Interacts(size_t a, size_t b) const {
    const BodyInfo& x = bodies[a];
    const BodyInfo& y = bodies[b];
    if (x.is_static && y.is_static) return false;
    return x.robot_id.empty() || x.robot_id != y.robot_id;
  }

  // `near` is a buffer for the targets a block of samples meets (Find's, reused pair after pair).
  void SamplesInto(uint32_t a, uint32_t b, const std::vector<WorldFrame>& world, std::vector<LocalFrame>* locals,
                   std::vector<uint32_t>* near, std::vector<ContactPoint>* contacts) const;
  const Shape* ShapeOf(uint32_t body, uint32_t geometry) const {
    for (const Shape& shape : shapes[body]) {
      if (shape.index == geometry) return &shape;
    }
    return nullptr;
  }
  // A cylinder standing on a box (StandsOn), for a pair of a sampled shape and a target, either way round; `local`
  // maps the sampled body's frame into the target's.
  static bool Standing(const Shape& own, const Shape& target, const LocalFrame& local) {
    using K = Geometry::Kind;
    if (own.kind == K::kCylinder && target.kind == K::kBox) {
      return StandsOn(target.half, local.rotation * own.position + local.translation,
                      local.rotation * own.rotation.col(2));
    }
    if (own.kind == K::kBox && target.kind == K::kCylinder) {
      // The cylinder's centre and axis in the sampled body's frame, then in the box's.
      const Vec3 centre = local.rotation.transpose() * -local.translation;
      const Vec3 axis = local.rotation.transpose().col(2);
      return StandsOn(own.half, own.rotation.transpose() * (centre - own.position), own.rotation.transpose() * axis);
    }
    return false;
  }
  // A cylinder's sample (body frame) on its side or its caps' rims.
  static bool OnRim(const Shape& cylinder, const Vec3& sample) {
    const Vec3 p = cylinder.rotation.transpose() * (sample - cylinder.position);
    return std::hypot(p.x(), p.y()) >= cylinder.radius * (1 - 1e-9);
  }
  // The support contacts of a's spheres and cylinders against b's primitives (SupportOf); uses the frames
  // SamplesInto set.
  void SupportsInto(uint32_t a, uint32_t b, const std::vector<WorldFrame>& world, const std::vector<LocalFrame>& locals,
                    std::vector<ContactPoint>* contacts) const;
  void SphereSupports(uint32_t a, uint32_t b, const Shape& sphere, const std::vector<WorldFrame>& world,
                      const std::vector<LocalFrame>& locals, std::vector<ContactPoint>* contacts) const;
  void RimSupports(uint32_t a, uint32_t b, const Shape& cylinder, const std::vector<WorldFrame>& world,
                   const std::vector<LocalFrame>& locals, std::vector<ContactPoint>* contacts) const;
};

ContactFinder::ContactFinder(const SceneModel& model, const ContactFinderOptions& options)
    : impl_(std::make_unique<Impl>(options)) {
  Impl& m = *impl_;
  // A zero or NaN spacing would ask for infinitely many samples.
  if (!(options.sample_spacing > 0) || !std::isfinite(options.sample_spacing)) {
    ThrowInvalidArgument("sample_spacing: " + std::to_string(options.sample_spacing) + " m is not a positive number");
  }
  if (!std::isfinite(options.margin)) {
    ThrowInvalidArgument("margin: " + std::to_string(options.margin) + " m is not finite");
  }
  const double margin = std::max(options.margin, 0.0);
  for (const BodySpec& body : model.bodies) {
    m.bodies.push_back({body.motion == BodyMotion::kStatic, body.robot_id});
    m.samples.push_back(collision::SampleBody(body, options.sample_spacing));
    std::vector<Shape>& shapes = m.shapes.emplace_back();
    std::vector<Geometry::Kind>& kinds = m.geometry_kinds.emplace_back();
    for (const Geometry& geometry : body.collision) kinds.push_back(geometry.kind);
    Aabb bounds;
    for (const Geometry& geometry : body.collision) {
      if (geometry.kind == Geometry::Kind::kMesh && !geometry.mesh) continue;
      Shape shape;
      shape.index = static_cast<uint32_t>(&geometry - body.collision.data());
      shape.kind = geometry.kind;
      shape.half = 0.5 * geometry.box_size;
      shape.radius = geometry.radius;
      shape.half_length = 0.5 * geometry.length;
      const Aabb local = collision::GeometryBounds(geometry);
      shape.cull = Grown(local, margin);
      shape.rotation = geometry.origin.orientation.toRotationMatrix();
      shape.position = geometry.origin.position;
      if (geometry.kind == Geometry::Kind::kMesh) {
        auto& bvh = m.meshes[geometry.mesh.get()];
        if (!bvh) bvh = std::make_unique<collision::MeshBvh>(geometry.mesh);
        shape.mesh = bvh.get();
      }
      bounds.Add(collision::TransformAabb(local, shape.rotation, shape.position));
      shapes.push_back(shape);
    }
    m.body_bounds.push_back(bounds);
    m.max_shapes = std::max(m.max_shapes, shapes.size());
  }
}

ContactFinder::~ContactFinder() = default;
ContactFinder::ContactFinder(ContactFinder&&) noexcept = default;
ContactFinder& ContactFinder::operator=(ContactFinder&&) noexcept = default;

const std::vector<Vec3>& ContactFinder::Samples(uint32_t body) const { return impl_->samples.at(body).points; }

void ContactFinder::Find(const std::vector<Pose>& body_poses, std::vector<ContactPoint>* contacts) const {
  const Impl& m = *impl_;
  const size_t n = m.bodies.size();
  if (body_poses.size() != n) {
    throw Error(ErrorCode::kInternal, "ContactFinder::Find: " + std::to_string(body_poses.size()) +
                                          " poses for " + std::to_string(n) + " bodies");
  }
  const double margin = std::max(m.options.margin, 0.0);
  FindBuffers& buffers = ThreadFindBuffers();
  std::vector<WorldFrame>& world = buffers.world;
  world.resize(n);
  for (size_t i = 0; i < n; ++i) {
    world[i].rotation = body_poses[i].orientation.toRotationMatrix();
    world[i].position = body_poses[i].position;
    world[i].bounds = Grown(collision::TransformAabb(m.body_bounds[i], world[i].rotation, world[i].position), margin);
  }
  std::vector<LocalFrame>& locals = buffers.locals;
  locals.resize(m.max_shapes);
  std::vector<uint32_t>& near = buffers.near;
  near.reserve(m.max_shapes);
  // Every ordered pair: (a, b) reports a's samples inside b, so walking a then b gives the promised order.
  // Quadratic in bodies, but a scene has tens of bodies and the box test is a few comparisons.
  for (uint32_t a = 0; a < n; ++a) {
    if (m.samples[a].points.empty()) continue;
    for (uint32_t b = 0; b < n; ++b) {
      if (b == a || m.shapes[b].empty() || !m.Interacts(a, b)) continue;
      if (world[a].bounds.Empty() || world[b].bounds.Empty() || !world[a].bounds.Overlaps(world[b].bounds)) continue;
      const size_t first = contacts->size();
      m.SamplesInto(a, b, world, &locals, &near, contacts);
      const size_t samples_end = contacts->size();
      m.SupportsInto(a, b, world, locals, contacts);
      // Samples come in feature order; support features sort after their sphere's samples: when there are
      // any, keep the pair's contacts in feature order.
      if (contacts->size() > samples_end) {
        std::sort(contacts->begin() + static_cast<std::ptrdiff_t>(first), contacts->end(),
                  [](const ContactPoint& x, const ContactPoint& y) { return x.feature < y.feature; });
      }
    }
  }
}

void ContactFinder::Impl::SamplesInto(uint32_t a, uint32_t b, const std::vector<WorldFrame>& world,
                                      std::vector<LocalFrame>* locals, std::vector<uint32_t>* near,
                                      std::vector<ContactPoint>* contacts) const {
  const WorldFrame& fa = world[a];
  const WorldFrame& fb = world[b];
  const std::vector<Shape>& targets = shapes[b];
  const double margin = std::max(options.margin, 0.0);

  // Where b's geometries are, seen from a's frame: blocks of a's samples outside this box are skipped whole, and
  // a block's samples are tested only against the geometries whose own box it meets (a cube's top samples never
  // meet the table's legs).
  Aabb query;
  for (size_t g = 0; g < targets.size(); ++g) {
    LocalFrame& local = (*locals)[g];
    local.world_rotation = fb.rotation * targets[g].rotation;
    const Vec3 origin = fb.rotation * targets[g].position + fb.position;
    local.rotation = local.world_rotation.transpose() * fa.rotation;
    local.translation = local.world_rotation.transpose() * (fa.position - origin);
    const Mat3 back = local.rotation.transpose();
    local.cull_in_sampled = collision::TransformAabb(targets[g].cull, back, -(back * local.translation));
    query.Add(local.cull_in_sampled);
  }

  const collision::BodySamples& own = samples[a];
  FindBuffers& buffers = ThreadFindBuffers();
  std::vector<Support>& supported = buffers.supported;  // how this block's geometry meets each target
  std::vector<std::array<uint8_t, 6>>& facing = buffers.facing;  // box on box: per target, per own face
  supported.assign(targets.size(), Support::kNone);
  facing.assign(targets.size(), {});
  uint32_t supported_geometry = std::numeric_limits<uint32_t>::max();  // the geometry the two above are for
  for (uint32_t index = 0; index < own.blocks.size(); ++index) {
    if (index % collision::kBlocksPerGroup == 0 && !own.groups[index / collision::kBlocksPerGroup].bounds.Overlaps(query)) {
      index += collision::kBlocksPerGroup - 1;  // the whole group is away from b
      continue;
    }
    const collision::SampleBlock& block = own.blocks[index];
    if (!block.bounds.Overlaps(query)) continue;
    near->clear();  // the targets whose box the block meets
    for (uint32_t g = 0; g < targets.size(); ++g) {
      if (block.bounds.Overlaps((*locals)[g].cull_in_sampled)) near->push_back(g);
    }
    if (near->empty()) continue;
    const auto geometry = static_cast<uint32_t>(own.features[block.begin] >> 32);  // a block is one geometry's
    const Geometry::Kind kind = geometry_kinds[a][geometry];
    const Shape* own_shape = ShapeOf(a, geometry);
    // supported and facing depend on the block's geometry only: a geometry's blocks follow one another, so they
    // are worked out once per geometry, not once per block.
    if (geometry != supported_geometry) {
      supported_geometry = geometry;
      for (size_t g = 0; g < targets.size(); ++g) {
        supported[g] = SupportOf(kind, targets[g].kind);
        if (supported[g] != Support::kNone && own_shape && Standing(*own_shape, targets[g], (*locals)[g])) {
          supported[g] = Support::kNone;
        }
        if (kind == Geometry::Kind::kBox && own_shape && targets[g].kind == Geometry::Kind::kBox) {
          facing[g] = FacingFaces(*own_shape, (*locals)[g].rotation);
        }
      }
    }
    const Shape* cylinder = kind == Geometry::Kind::kCylinder ? own_shape : nullptr;
    const bool box_on_box = kind == Geometry::Kind::kBox && own_shape;
    for (uint32_t k = block.begin; k < block.end; ++k) {
      const Vec3& s = own.points[k];
      // The faces the sample lies on, worked out only for a sample inside a box target's cull box (most are not).
      unsigned own_faces = 0;
      bool faces_known = !box_on_box;
      // With several geometries, the one the sample is deepest in decides (ties: the first).
      double best_depth = -std::numeric_limits<double>::infinity();
      size_t best = targets.size();
      Vec3 best_normal = Vec3::UnitZ();
      for (const uint32_t g : *near) {
        if (supported[g] == Support::kAll || (supported[g] == Support::kRim && OnRim(*cylinder, s))) continue;
        const LocalFrame& local = (*locals)[g];
        const Vec3 p = local.rotation * s + local.translation;
        if (!targets[g].cull.Contains(p)) continue;
        const Shape& shape = targets[g];
        double depth = 0;
        Vec3 normal;
        switch (shape.kind) {
          case Geometry::Kind::kBox:
            if (!faces_known) own_faces = FacesOf(*own_shape, s), faces_known = true;
            depth = own_faces ? collision::BoxDepthThrough(shape.half, p, Through(facing[g], own_faces), &normal)
                              : collision::BoxDepth(shape.half, p, &normal);
            break;
          case Geometry::Kind::kSphere:
            depth = collision::SphereDepth(shape.radius, p, &normal);
            break;
          case Geometry::Kind::kCylinder:
            depth = collision::CylinderDepth(shape.radius, shape.half_length, p, &normal);
            break;
          case Geometry::Kind::kMesh:
            if (!shape.mesh->Depth(p, margin, &depth, &normal)) continue;
            break;
        }
        if (depth > -margin && depth > best_depth) {
          best_depth = depth;
          best = g;
          best_normal = normal;
        }
      }
      if (best == targets.size()) continue;
      ContactPoint& c = contacts->emplace_back();
      c.body_a = a;
      c.body_b = b;
      c.feature = own.features[k];
      c.point = fa.rotation * s + fa.position;
      c.normal = (*locals)[best].world_rotation * best_normal;
      c.depth = best_depth;
    }
  }
}

void ContactFinder::Impl::SupportsInto(uint32_t a, uint32_t b, const std::vector<WorldFrame>& world,
                                       const std::vector<LocalFrame>& locals,
                                       std::vector<ContactPoint>* contacts) const {
  for (const Shape& own : shapes[a]) {
    if (own.kind == Geometry::Kind::kSphere) {
      SphereSupports(a, b, own, world, locals, contacts);
    } else if (own.kind == Geometry::Kind::kCylinder) {
      RimSupports(a, b, own, world, locals, contacts);
    }
  }
}

void ContactFinder::Impl::SphereSupports(uint32_t a, uint32_t b, const Shape& sphere, const std::vector<WorldFrame>& world,
                                         const std::vector<LocalFrame>& locals,
                                         std::vector<ContactPoint>* contacts) const {
  const std::vector<Shape>& targets = shapes[b];
  const double margin = std::max(options.margin, 0.0);
  for (size_t g = 0; g < targets.size(); ++g) {
    const Shape& target = targets[g];
    // Two spheres meet once: the pair's lower body reports it.
    if (!IsPrimitive(target.kind) || (target.kind == Geometry::Kind::kSphere && a > b)) continue;
    const LocalFrame& local = locals[g];
    const Vec3 centre = local.rotation * sphere.position + local.translation;  // in the target's frame
    if (!Grown(target.cull, sphere.radius).Contains(centre)) continue;
    Vec3 normal;
    const double depth = sphere.radius + PrimitiveDepth(target, centre, &normal);
    if (!(depth > -margin)) continue;
    ContactPoint& c = contacts->emplace_back();
    c.body_a = a;
    c.body_b = b;
    c.feature = static_cast<uint64_t>(sphere.index) << 32 | (kSupportFeature | target.index);
    c.normal = local.world_rotation * normal;
    // The sphere's deepest point: its centre, one radius against the normal.
    c.point = world[a].rotation * sphere.position + world[a].position - sphere.radius * c.normal;
    c.depth = depth;
  }
}

void ContactFinder::Impl::RimSupports(uint32_t a, uint32_t b, const Shape& cylinder, const std::vector<WorldFrame>& world,
                                      const std::vector<LocalFrame>& locals,
                                      std::vector<ContactPoint>* contacts) const {
  const std::vector<Shape>& targets = shapes[b];
  const double margin = std::max(options.margin, 0.0);
  const Vec3 axis_body = cylinder.rotation.col(2);
  for (size_t g = 0; g < targets.size(); ++g) {
    const Shape& target = targets[g];
    if (target.kind != Geometry::Kind::kBox) continue;
    const LocalFrame& local = locals[g];
    const Vec3 centre = local.rotation * cylinder.position + local.translation;  // in the box's frame
    const double reach = std::hypot(cylinder.radius, cylinder.half_length);
    if (!Grown(target.cull, reach).Contains(centre) || Standing(cylinder, target, local)) continue;
    // Toward the box: against the normal of the box's surface nearest the centre.
    Vec3 face;
    collision::BoxDepth(target.half, centre, &face);
    const Vec3 axis = local.rotation * axis_body;
    const Vec3 across = -face - (-face).dot(axis) * axis;  // the down direction within the caps' planes
    if (across.norm() < 1e-6) continue;  // standing (caught above; kept for the division)
    const Vec3 down = across.normalized();
    // The cylinder's line nearest the box, P(t) = base + t h axis for t in [-1, 1], clipped to the box's extent
    // across the face normal: a rod lying over an edge touches where it crosses the edge, not at its caps.
    const Vec3 base = centre + cylinder.radius * down;
    double t0 = -1, t1 = 1;
    int face_axis = 0;  // the face's axis (beyond an edge or a corner, the normal's largest component)
    face.cwiseAbs().maxCoeff(&face_axis);
    Vec3 normal = Vec3::Zero();
    normal[face_axis] = face[face_axis] < 0 ? -1 : 1;
    for (int j = 0; j < 3 && t0 <= t1; ++j) {
      if (j == face_axis) continue;
      const double slope = cylinder.half_length * axis[j];
      if (std::abs(slope) < 1e-12) {
        if (std::abs(base[j]) > target.half[j]) t1 = t0 - 1;  // parallel and beside the box
        continue;
      }
      double lo = (-target.half[j] - base[j]) / slope, hi = (target.half[j] - base[j]) / slope;
      if (lo > hi) std::swap(lo, hi);
      t0 = std::max(t0, lo);
      t1 = std::min(t1, hi);
    }
    if (t0 > t1) continue;
    for (int cap = 0; cap < (t1 > t0 ? 2 : 1); ++cap) {
      const Vec3 p = base + (cap == 0 ? t0 : t1) * cylinder.half_length * axis;
      // Depth below the face (the clipped line lies over it; at its edge the box's own nearest face would be the
      // side one, 0 deep).
      const double depth = target.half[face_axis] - normal[face_axis] * p[face_axis];
      if (!(depth > -margin)) continue;
      ContactPoint& c = contacts->emplace_back();
      c.body_a = a;
      c.body_b = b;
      c.feature = static_cast<uint64_t>(cylinder.index) << 32 | (kSupportFeature | (target.index << 1) | cap);
      c.normal = local.world_rotation * normal;
      // p back from the box's frame into a's body frame, then the world.
      const Vec3 body_point = local.rotation.transpose() * (p - local.translation);
      c.point = world[a].rotation * body_point + world[a].position;
      c.depth = depth;
    }
  }
}

}  // namespace graspsim
