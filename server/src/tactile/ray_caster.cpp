// Tactile pads' segments cast into Embree BVHs of every body (see ray_caster.h).
#include "tactile/ray_caster.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "collision/aabb.h"
#include "collision/embree.h"
#include "collision/tessellation.h"
#include "core/error.h"
#include "tactile/near_triangles.h"
#include "tactile/segment_box.h"

namespace graspsim {
namespace {

using collision::Aabb;
using collision::BoxMesh;
using collision::CylinderMesh;
using collision::LocalMesh;
using collision::SphereMesh;

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// How far a pad may move relative to a mesh before its segments' candidate triangles are gathered again
// (tactile/near_triangles.h): a held object slips far less per step; wider costs more candidates per segment.
constexpr double kNearSlack = 0.5e-3;  // m

// One body's collision geometry as the rays see it, in the body frame. A body that is a single box (a cube, a
// table top) is met analytically by the slab test in double precision: exact, and several times cheaper per
// segment than Embree's traversal of its 12 triangles. Everything else is a triangle mesh: each segment is
// tested against the triangles near it (tactile/near_triangles.h); Embree's BVH says which side of the surface
// a base is on when its segment meets none of them.
struct Target {
  std::optional<collision::EmbreeScene> scene;  // Embree's BVH, or none
  SegmentMesh triangles;       // the same triangles (Embree's primitive order) with their unit normals
  bool is_box = false;         // the single-box case: box_frame and box_extent instead of scene
  Pose box_frame;              // the box's frame in the body frame
  Aabb box_extent;             // the box in its own frame, ±half size
  Aabb bounds;                 // body frame: of the triangles, grown by float slack, or of the box
  std::string robot_id;
  bool HasGeometry() const { return scene.has_value() || is_box; }
};

struct Pad {
  std::vector<PadElement> elements;
  size_t link = 0;             // body index
  Pose origin;
  double thickness = 0;
  Aabb foam;                   // pad frame: every element's segment
  std::vector<double> x, y, z;  // the elements' positions, one array per coordinate (SegmentEntries)
  std::vector<uint32_t> normal_runs;  // the end of each run of elements that share their normal
  // Per run, a rotation from the pad frame to one whose z is the run's normal, and per element its position
  // there: the frame the mesh path tests segments in.
  std::vector<Mat3> run_rotations;
  std::vector<Vec3> run_positions;
};

}  // namespace

struct TactileRayCaster::Impl {
  std::vector<Target> bodies;
  std::vector<Pad> pads;
  // Scratch of Cast, sized in the constructor so Cast allocates nothing (Cast is therefore not reentrant).
  mutable collision::RayBatch rays;                // one pad's segments against one body
  mutable std::vector<double> best_depth, best_t;  // per element of the current pad; depth 0: no hit
  mutable std::vector<uint32_t> best_body;
  // Per pad and mesh body (pad * bodies.size() + body): the segments' candidate triangles, and whether each
  // element's base was inside the body when they were gathered (meaningful where NearTriangles::BaseClear).
  struct MeshCandidates {
    NearTriangles triangles;
    std::vector<uint8_t> base_inside;
  };
  mutable std::vector<MeshCandidates> near;
  mutable std::vector<Vec3> run_points;  // a run's candidate triangles' vertices in its segments' frame
  mutable std::vector<double> entries;             // per element of the current pad: SegmentEntries' answer
  mutable std::vector<Aabb> world_bounds;          // per body
  mutable uint64_t ray_count = 0;

  void Build(const BodySpec& body, Target* target);
  // The segments of `pad` against the single box of `target` (to_box: pad frame → box frame), body index b.
  void CastAtBox(const Pad& pad, const Target& target, const Pose& to_box, uint32_t b) const;
  // Gathers the candidate triangles of `pad`'s segments in `target` at the pad → body map, and the sides of
  // their bases.
  void Gather(const Pad& pad, const Target& target, const Mat3& rotation, const Vec3& translation,
              MeshCandidates* near_pad) const;
  // The segments of pad `p` against the mesh of `target` (to_body: pad frame → body frame), body index b.
  void CastAtMesh(const Pad& pad, uint32_t p, const Target& target, const Pose& to_body, uint32_t b) const;
  // Casts `rays` (from elements' bases to infinity) into target's BVH and calls inside(element) for each ray
  // whose first hit leaves the surface: its base is inside the body.
  template <typename Inside>
  void BasesInside(const Target& target, Inside inside) const {
    if (rays.size() == 0) return;
    target.scene->Intersect(&rays);
    for (size_t i = 0; i < rays.size(); ++i) {
      if (rays.Hit(i) && target.triangles.normals[rays.Triangle(i)].dot(rays.Direction(i)) > 0) inside(rays.Id(i));
    }
  }
  // The deepest hit over the bodies per element; ties stay with the lower body index (bodies go in order).
  void KeepDeepest(uint32_t element, double depth, double t, uint32_t b) const {
    if (depth > best_depth[element]) {
      best_depth[element] = depth;
      best_t[element] = t;
      best_body[element] = b;
    }
  }
};

void TactileRayCaster::Impl::CastAtBox(const Pad& pad, const Target& target, const Pose& to_box, uint32_t b) const {
  // The same answers as the Embree path: a base inside the box is fully compressed (t = 0); otherwise the
  // segment's entry into the box, if it lies within the foam.
  const Mat3 rotation = to_box.orientation.toRotationMatrix();
  const PointColumns points{pad.x.data(), pad.y.data(), pad.z.data()};
  uint32_t begin = 0;
  for (const uint32_t end : pad.normal_runs) {
    SegmentDirection direction;
    direction.Set(rotation * pad.elements[begin].normal);
    const PointColumns run{points.x + begin, points.y + begin, points.z + begin};
    // A base inside the (closed) box meets it at entry 0, so the slab test alone answers both cases.
    SegmentEntries(run, end - begin, rotation, to_box.position, direction, pad.thickness, target.box_extent,
                   entries.data() + begin);
    begin = end;
  }
  for (uint32_t e = 0; e < pad.elements.size(); ++e) {
    const double entry = entries[e];  // ≥ 0 (the depth is at most the thickness), or infinite: a miss
    if (entry == std::numeric_limits<double>::infinity()) continue;
    ++ray_count;
    const double depth = pad.thickness - entry;
    if (depth > 0) KeepDeepest(e, depth, entry, b);
  }
}

void TactileRayCaster::Impl::Gather(const Pad& pad, const Target& target, const Mat3& rotation,
                                    const Vec3& translation, MeshCandidates* near_pad) const {
  near_pad->triangles.Gather(target.triangles, pad.elements, pad.normal_runs, pad.thickness, pad.foam, rotation,
                             translation, kNearSlack);
  // Which side of the surface each clear base is on: a ray from it to infinity, inside when its first hit leaves
  // (a base outside the body's box is outside).
  near_pad->base_inside.assign(pad.elements.size(), 0);
  rays.Clear();
  for (uint32_t e = 0; e < pad.elements.size(); ++e) {
    const Vec3 o = rotation * pad.elements[e].position + translation;
    if (near_pad->triangles.BaseClear(e) && target.bounds.Contains(o)) {
      rays.Add(o, (rotation * pad.elements[e].normal).normalized(), kInfinity, e);
    }
  }
  BasesInside(target, [&](uint32_t e) { near_pad->base_inside[e] = 1; });
}

void TactileRayCaster::Impl::CastAtMesh(const Pad& pad, uint32_t p, const Target& target, const Pose& to_body,
                                        uint32_t b) const {
  // Pad frame → body frame in one map, so each element costs a matrix-vector product.
  const Mat3 rotation = to_body.orientation.toRotationMatrix();
  MeshCandidates& near_pad = near[p * bodies.size() + b];
  const NearTriangles& candidates = near_pad.triangles;
  if (!candidates.Covers(rotation, to_body.position)) Gather(pad, target, rotation, to_body.position, &near_pad);
  rays.Clear();
  uint32_t run_start = 0;
  for (size_t r = 0; r < pad.normal_runs.size(); ++r) {
    const uint32_t run_stop = pad.normal_runs[r];
    SegmentDirection direction;
    direction.Set(rotation * pad.elements[run_start].normal);
    // The run's triangles into the frame its segments run along z in (body → pad → run), vertex by vertex.
    const Mat3 to_run = pad.run_rotations[r] * rotation.transpose();
    const Vec3 shift = -(to_run * to_body.position);
    run_points.resize(candidates.run_vertex_count(r));
    const Vec3* vertices = candidates.run_vertices(r);
    for (size_t k = 0; k < run_points.size(); ++k) run_points[k] = to_run * vertices[k] + shift;
    const std::array<uint32_t, 3>* run_corners = candidates.run_corners(r);
    const uint32_t* run_triangles = candidates.run_triangles(r);
    for (uint32_t e = run_start; e < run_stop; ++e) {
      const Vec3 o = rotation.lazyProduct(pad.elements[e].position) + to_body.position;
      // A segment that misses the body's box can neither enter it nor start inside it.
      if (!SegmentMeetsBox(o, direction, pad.thickness, target.bounds)) continue;
      ++ray_count;
      double first = std::numeric_limits<double>::infinity(), t = 0;
      uint32_t hit = 0;
      const Vec3& origin = pad.run_positions[e];
      for (const uint32_t* k = candidates.begin(e); k != candidates.end(e); ++k) {
        const std::array<uint32_t, 3>& c = run_corners[*k];
        // Candidates come in ascending triangle order: of two at the same distance the lower index stays.
        if (SegmentAlongZMeetsTriangle(origin, run_points[c[0]], run_points[c[1]], run_points[c[2]], pad.thickness,
                                       &t) &&
            t < first) {
          first = t;
          hit = run_triangles[*k];
        }
      }
      if (first <= pad.thickness) {
        const double facing = target.triangles.normals[hit].dot(direction.d);
        if (facing < 0 && first < pad.thickness) {
          KeepDeepest(e, pad.thickness - first, first, b);  // enters the surface
        } else if (facing > 0 && target.bounds.Contains(o)) {
          KeepDeepest(e, pad.thickness, 0, b);  // leaves first: the base is inside (outside the box it cannot be)
        }
      } else if (candidates.BaseClear(e)) {
        if (near_pad.base_inside[e]) KeepDeepest(e, pad.thickness, 0, b);  // buried deeper than the foam
      } else if (target.bounds.Contains(o)) {
        // Nothing within the foam from a base inside the box and near the surface: buried deeper than the foam,
        // or outside. The rest of the ray tells (its first hit leaves, or enters beyond the foam).
        rays.Add(o, direction.d, kInfinity, e);
      }
    }
    run_start = run_stop;
  }
  BasesInside(target, [&](uint32_t e) { KeepDeepest(e, pad.thickness, 0, b); });
}

void TactileRayCaster::Impl::Build(const BodySpec& body, Target* target) {
  target->robot_id = body.robot_id;
  if (body.collision.size() == 1 && body.collision[0].kind == Geometry::Kind::kBox) {
    const Geometry& g = body.collision[0];
    target->is_box = true;
    target->box_frame = g.origin;
    target->box_extent.lo = -0.5 * g.box_size;
    target->box_extent.hi = 0.5 * g.box_size;
    target->bounds = collision::TransformAabb(target->box_extent, g.origin.orientation.toRotationMatrix(),
                                              g.origin.position);
    return;
  }
  TriangleMesh mesh;  // body frame
  for (const Geometry& g : body.collision) {
    LocalMesh local;
    switch (g.kind) {
      case Geometry::Kind::kBox:
        local = BoxMesh(0.5 * g.box_size);
        break;
      case Geometry::Kind::kSphere:
        local = SphereMesh(g.radius);
        break;
      case Geometry::Kind::kCylinder:
        local = CylinderMesh(g.radius, 0.5 * g.length);
        break;
      case Geometry::Kind::kMesh:
        if (!g.mesh) continue;
        for (const auto& v : g.mesh->vertices) local.vertices.push_back(v.cast<double>());
        local.triangles = g.mesh->triangles;
        break;
    }
    const uint32_t base = static_cast<uint32_t>(mesh.vertices.size());
    for (const Vec3& v : local.vertices) {
      mesh.vertices.push_back((g.origin * v).cast<float>());
      target->triangles.vertices.push_back(mesh.vertices.back().cast<double>());
    }
    // Normals from the float vertices Embree will intersect; zero-area triangles are dropped (no normal to give).
    auto at = [&](uint32_t i) { return Vec3(mesh.vertices[base + i].cast<double>()); };
    for (const auto& t : local.triangles) {
      const Vec3 n = (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0]));
      if (!(n.squaredNorm() > 0)) continue;
      mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
      target->triangles.AddTriangle(mesh.triangles.back(), n.normalized());
    }
  }
  if (mesh.triangles.empty()) return;
  for (const Eigen::Vector3f& v : mesh.vertices) target->bounds.Add(Vec3(v.cast<double>()));
  // Float vertices and float rays: grow the box a little so the culling never drops a hit on its faces.
  const double slack = 1e-6 * (target->bounds.hi - target->bounds.lo).maxCoeff() + 1e-9;
  target->bounds.lo.array() -= slack;
  target->bounds.hi.array() += slack;

  // Built once per model and cast against every step: spend the build time on a high-quality BVH.
  target->scene.emplace(mesh, RTC_BUILD_QUALITY_HIGH);
}

TactileRayCaster::TactileRayCaster(const SceneModel& model) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.bodies.resize(model.bodies.size());
  // Without pads nothing is ever cast: a scene of meshes must not pay for a second set of BVHs.
  if (!model.tactile_arrays.empty()) {
    for (size_t b = 0; b < model.bodies.size(); ++b) m.Build(model.bodies[b], &m.bodies[b]);
  }
  size_t max_elements = 0;
  for (const TactileArraySpec& spec : model.tactile_arrays) {
    Pad& pad = m.pads.emplace_back();
    const auto link = model.body_index.find(spec.body_id);
    if (link == model.body_index.end()) {
      ThrowInvalidArgument("tactile array '" + spec.id + "': no body '" + spec.body_id + "'");
    }
    pad.link = link->second;
    pad.origin = spec.origin;
    pad.thickness = spec.thickness;
    pad.elements = MakePadElements(spec);
    for (const PadElement& e : pad.elements) {
      pad.foam.Add(e.position);
      pad.foam.Add(e.position + spec.thickness * e.normal);
      pad.x.push_back(e.position.x());
      pad.y.push_back(e.position.y());
      pad.z.push_back(e.position.z());
      const size_t i = &e - pad.elements.data();
      if (i > 0 && e.normal != pad.elements[pad.normal_runs.empty() ? 0 : pad.normal_runs.back()].normal) {
        pad.normal_runs.push_back(static_cast<uint32_t>(i));
      }
    }
    if (!pad.elements.empty()) pad.normal_runs.push_back(static_cast<uint32_t>(pad.elements.size()));
    uint32_t run_start = 0;
    for (const uint32_t run_stop : pad.normal_runs) {
      const Vec3 n = pad.elements[run_start].normal.normalized();
      const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
      Mat3 to_run;
      to_run << u.transpose(), v.transpose(), n.transpose();
      pad.run_rotations.push_back(to_run);
      for (uint32_t e = run_start; e < run_stop; ++e) pad.run_positions.push_back(to_run * pad.elements[e].position);
      run_start = run_stop;
    }
    max_elements = std::max(max_elements, pad.elements.size());
  }
  m.rays.rays.reserve(max_elements);
  m.best_depth.resize(max_elements);
  m.best_t.resize(max_elements);
  m.best_body.resize(max_elements);
  m.near.resize(m.pads.size() * m.bodies.size());
  m.entries.resize(max_elements);
  m.world_bounds.resize(m.bodies.size());
}

TactileRayCaster::~TactileRayCaster() = default;
TactileRayCaster::TactileRayCaster(TactileRayCaster&&) noexcept = default;
TactileRayCaster& TactileRayCaster::operator=(TactileRayCaster&&) noexcept = default;

const std::vector<PadElement>& TactileRayCaster::Elements(uint32_t pad) const { return impl_->pads.at(pad).elements; }

uint64_t TactileRayCaster::last_ray_count() const { return impl_->ray_count; }

uint64_t TactileRayCaster::candidate_gathers() const {
  uint64_t gathers = 0;
  for (const Impl::MeshCandidates& near : impl_->near) gathers += near.triangles.gathers();
  return gathers;
}

void TactileRayCaster::Cast(const std::vector<Pose>& body_poses, std::vector<PadHit>* hits) const {
  const Impl& m = *impl_;
  if (body_poses.size() != m.bodies.size()) {
    throw Error(ErrorCode::kInternal, "TactileRayCaster::Cast: " + std::to_string(body_poses.size()) +
                                          " poses for " + std::to_string(m.bodies.size()) + " bodies");
  }
  m.ray_count = 0;
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    if (!m.bodies[b].HasGeometry()) continue;
    m.world_bounds[b] = collision::TransformAabb(m.bodies[b].bounds, body_poses[b].orientation.toRotationMatrix(),
                                                 body_poses[b].position);
  }
  for (uint32_t p = 0; p < m.pads.size(); ++p) {
    const Pad& pad = m.pads[p];
    const size_t n = pad.elements.size();
    if (n == 0 || !(pad.thickness > 0)) continue;
    const Pose pad_world = body_poses[pad.link] * pad.origin;
    const Mat3 pad_rotation = pad_world.orientation.toRotationMatrix();
    const Aabb foam = collision::TransformAabb(pad.foam, pad_rotation, pad_world.position);
    const std::string& own_robot = m.bodies[pad.link].robot_id;
    std::fill_n(m.best_depth.begin(), n, 0.0);

    for (uint32_t b = 0; b < m.bodies.size(); ++b) {
      const Target& target = m.bodies[b];
      if (b == pad.link || !target.HasGeometry()) continue;
      if (!own_robot.empty() && target.robot_id == own_robot) continue;  // the hand never senses itself
      if (!m.world_bounds[b].Overlaps(foam)) continue;
      if (target.is_box) {
        m.CastAtBox(pad, target, (body_poses[b] * target.box_frame).Inverse() * pad_world, b);
        continue;
      }
      m.CastAtMesh(pad, p, target, body_poses[b].Inverse() * pad_world, b);
    }
    uint32_t run_begin = 0;
    for (const uint32_t run_end : pad.normal_runs) {  // one world normal per run of elements that share theirs
      const Vec3 world_normal = pad_rotation * pad.elements[run_begin].normal;
      for (uint32_t e = run_begin; e < run_end; ++e) {
        if (m.best_depth[e] <= 0) continue;
        const PadElement& element = pad.elements[e];
        hits->push_back({p, e, m.best_body[e], m.best_depth[e],
                         pad_rotation.lazyProduct(element.position) + pad_world.position + m.best_t[e] * world_normal,
                         world_normal});
      }
      run_begin = run_end;
    }
  }
}

}  // namespace graspsim
