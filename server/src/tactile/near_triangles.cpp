// Candidate triangles per pad element and the watertight segment–triangle test (see near_triangles.h).
#include "tactile/near_triangles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace graspsim {
namespace {

double Cross(const Eigen::Vector2d& p, const Eigen::Vector2d& q) { return p.x() * q.y() - p.y() * q.x(); }

// The distance from the origin to the triangle (a, b, c) of the plane (0 inside it).
double DistanceFromOrigin(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const double u = Cross(a, b), v = Cross(b, c), w = Cross(c, a);
  if ((u >= 0 && v >= 0 && w >= 0) || (u <= 0 && v <= 0 && w <= 0)) return 0;
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& [p, q] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
    const Eigen::Vector2d edge = q - p;
    const double squared = edge.squaredNorm();
    const double t = squared > 0 ? std::clamp(-p.dot(edge) / squared, 0.0, 1.0) : 0.0;
    nearest = std::min(nearest, (p + t * edge).norm());
  }
  return nearest;
}

}  // namespace

void SegmentMesh::AddTriangle(const std::array<uint32_t, 3>& corners, const Vec3& normal) {
  triangles.push_back(corners);
  collision::Aabb& box = boxes.emplace_back();
  for (const uint32_t v : corners) box.Add(vertices[v]);
  normals.push_back(normal);
}

bool NearTriangles::Covers(const Mat3& rotation, const Vec3& translation) const {
  // A point x of the foam moves by (R − R₀) x + (p − p₀): at most ‖R − R₀‖_F |x| + |p − p₀|.
  return valid_ && (rotation - rotation_).norm() * reach_ + (translation - translation_).norm() < slack_;
}

void NearTriangles::Gather(const SegmentMesh& mesh, const std::vector<PadElement>& elements,
                           const std::vector<uint32_t>& run_ends, double length, const collision::Aabb& foam,
                           const Mat3& rotation, const Vec3& translation, double slack) {
  valid_ = true;
  rotation_ = rotation;
  translation_ = translation;
  slack_ = slack;
  reach_ = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 x((corner & 1 ? foam.hi : foam.lo).x(), (corner & 2 ? foam.hi : foam.lo).y(),
                 (corner & 4 ? foam.hi : foam.lo).z());
    reach_ = std::max(reach_, x.norm());
  }
  ++gathers_;

  // First the triangles near the whole foam, then each segment's share of them.
  collision::Aabb near = collision::TransformAabb(foam, rotation, translation);
  near.lo.array() -= slack;
  near.hi.array() += slack;
  near_foam_.clear();
  for (uint32_t i = 0; i < mesh.boxes.size(); ++i) {
    if (mesh.boxes[i].Overlaps(near)) near_foam_.push_back(i);
  }
  // Each run's triangles in ascending order, and each element's candidates as positions among them.
  constexpr uint32_t kNone = ~0u;
  position_of_.assign(mesh.boxes.size(), kNone);
  vertex_of_.assign(mesh.vertices.size(), kNone);
  first_.assign(elements.size() + 1, 0);
  base_clear_.assign(elements.size(), 1);
  run_first_.assign(1, 0);
  run_triangles_.clear();
  run_corners_.clear();
  run_vertex_first_.assign(1, 0);
  run_vertices_.clear();
  positions_.clear();
  uint32_t run_start = 0;
  for (const uint32_t run_stop : run_ends) {
    const size_t run_offset = run_triangles_.size(), vertex_offset = run_vertices_.size();
    // Across the segments (the plane normal to them): a triangle that does not come within `slack` of the
    // segment's line there cannot meet it after a move of less than `slack`.
    const Vec3 d = (rotation * elements[run_start].normal).normalized();
    const Vec3 across_u = d.unitOrthogonal(), across_v = d.cross(across_u);
    for (uint32_t e = run_start; e < run_stop; ++e) {
      const Vec3 o = rotation * elements[e].position + translation;
      auto across = [&](const Vec3& x) { return Eigen::Vector2d((x - o).dot(across_u), (x - o).dot(across_v)); };
      collision::Aabb segment, base;
      segment.Add(o);
      segment.Add(o + length * d);
      base.Add(o);
      for (collision::Aabb* box : {&segment, &base}) {
        box->lo.array() -= slack;
        box->hi.array() += slack;
      }
      for (const uint32_t i : near_foam_) {
        if (!mesh.boxes[i].Overlaps(segment)) continue;
        if (mesh.boxes[i].Overlaps(base)) base_clear_[e] = 0;
        const auto& t = mesh.triangles[i];
        // 1 nm over the slack: rounding in the projection never drops a candidate.
        if (DistanceFromOrigin(across(mesh.vertices[t[0]]), across(mesh.vertices[t[1]]), across(mesh.vertices[t[2]])) >
            slack + 1e-9) {
          continue;
        }
        if (position_of_[i] == kNone) {
          position_of_[i] = static_cast<uint32_t>(run_triangles_.size() - run_offset);
          run_triangles_.push_back(i);
          std::array<uint32_t, 3>& corners = run_corners_.emplace_back();
          for (int j = 0; j < 3; ++j) {
            const uint32_t v = mesh.triangles[i][j];
            if (vertex_of_[v] == kNone) {
              vertex_of_[v] = static_cast<uint32_t>(run_vertices_.size() - vertex_offset);
              run_vertices_.push_back(mesh.vertices[v]);
            }
            corners[j] = vertex_of_[v];
          }
        }
        positions_.push_back(position_of_[i]);
      }
      first_[e + 1] = static_cast<uint32_t>(positions_.size());
    }
    // Cleared run by run: a triangle two runs share is listed in both.
    for (size_t k = run_offset; k < run_triangles_.size(); ++k) {
      position_of_[run_triangles_[k]] = kNone;
      for (const uint32_t v : mesh.triangles[run_triangles_[k]]) vertex_of_[v] = kNone;
    }
    run_first_.push_back(static_cast<uint32_t>(run_triangles_.size()));
    run_vertex_first_.push_back(static_cast<uint32_t>(run_vertices_.size()));
    run_start = run_stop;
  }
}

}  // namespace graspsim
