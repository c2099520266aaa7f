// ContactFinder: body pairs culled by world boxes, then every surface sample of one body tested against the
// other body's geometries (exact distance for primitives, Embree for meshes). See contact_finder.h.
#include "collision/contact_finder.h"

#include <cmath>
#include <limits>
#include <map>
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
};

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
};

Aabb Grown(const Aabb& box, double margin) { return {box.lo.array() - margin, box.hi.array() + margin}; }

bool Contains(const Aabb& box, const Vec3& p) {
  return p.x() >= box.lo.x() && p.x() <= box.hi.x() && p.y() >= box.lo.y() && p.y() <= box.hi.y() &&
         p.z() >= box.lo.z() && p.z() <= box.hi.z();
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
  collision::EmbreeDevice device;
  std::map<const TriangleMesh*, std::unique_ptr<collision::MeshBvh>> meshes;  // one BVH per distinct mesh
  std::vector<collision::BodySamples> samples;  // per body
  std::vector<std::vector<Shape>> shapes;       // per body
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

  void SamplesInto(uint32_t a, uint32_t b, const std::vector<WorldFrame>& world, std::vector<LocalFrame>* locals,
                   std::vector<ContactPoint>* contacts) const;
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
    Aabb bounds;
    for (const Geometry& geometry : body.collision) {
      if (geometry.kind == Geometry::Kind::kMesh && !geometry.mesh) continue;
      Shape shape;
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
        if (!bvh) bvh = std::make_unique<collision::MeshBvh>(m.device.get(), geometry.mesh);
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
  std::vector<WorldFrame> world(n);
  for (size_t i = 0; i < n; ++i) {
    world[i].rotation = body_poses[i].orientation.toRotationMatrix();
    world[i].position = body_poses[i].position;
    world[i].bounds = Grown(collision::TransformAabb(m.body_bounds[i], world[i].rotation, world[i].position), margin);
  }
  std::vector<LocalFrame> locals(m.max_shapes);
  // Every ordered pair: (a, b) reports a's samples inside b, so walking a then b gives the promised order.
  // Quadratic in bodies, but a scene has tens of bodies and the box test is a few comparisons.
  for (uint32_t a = 0; a < n; ++a) {
    if (m.samples[a].points.empty()) continue;
    for (uint32_t b = 0; b < n; ++b) {
      if (b == a || m.shapes[b].empty() || !m.Interacts(a, b)) continue;
      if (world[a].bounds.Empty() || world[b].bounds.Empty() || !world[a].bounds.Overlaps(world[b].bounds)) continue;
      m.SamplesInto(a, b, world, &locals, contacts);
    }
  }
}

void ContactFinder::Impl::SamplesInto(uint32_t a, uint32_t b, const std::vector<WorldFrame>& world,
                                      std::vector<LocalFrame>* locals, std::vector<ContactPoint>* contacts) const {
  const WorldFrame& fa = world[a];
  const WorldFrame& fb = world[b];
  const std::vector<Shape>& targets = shapes[b];
  const double margin = std::max(options.margin, 0.0);

  // Where b's geometries are, seen from a's frame: blocks of a's samples outside this box are skipped whole.
  Aabb query;
  for (size_t g = 0; g < targets.size(); ++g) {
    LocalFrame& local = (*locals)[g];
    local.world_rotation = fb.rotation * targets[g].rotation;
    const Vec3 origin = fb.rotation * targets[g].position + fb.position;
    local.rotation = local.world_rotation.transpose() * fa.rotation;
    local.translation = local.world_rotation.transpose() * (fa.position - origin);
    const Mat3 back = local.rotation.transpose();
    query.Add(collision::TransformAabb(targets[g].cull, back, -(back * local.translation)));
  }

  const collision::BodySamples& own = samples[a];
  for (const collision::SampleBlock& block : own.blocks) {
    if (!block.bounds.Overlaps(query)) continue;
    for (uint32_t k = block.begin; k < block.end; ++k) {
      const Vec3& s = own.points[k];
      // With several geometries, the one the sample is deepest in decides (ties: the first).
      double best_depth = -std::numeric_limits<double>::infinity();
      size_t best = targets.size();
      Vec3 best_normal = Vec3::UnitZ();
      for (size_t g = 0; g < targets.size(); ++g) {
        const LocalFrame& local = (*locals)[g];
        const Vec3 p = local.rotation * s + local.translation;
        if (!Contains(targets[g].cull, p)) continue;
        const Shape& shape = targets[g];
        double depth = 0;
        Vec3 normal;
        switch (shape.kind) {
          case Geometry::Kind::kBox:
            depth = collision::BoxDepth(shape.half, p, &normal);
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

}  // namespace graspsim
