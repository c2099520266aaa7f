// A pad's segments against a triangle mesh without a BVH walk per segment (tactile/ray_caster.cpp's mesh path).
//
// A grasped object barely moves relative to the pad that holds it, so the triangles each element's segment can
// meet are gathered once — every triangle whose box comes within `slack` of the segment's box and whose
// projection across the segment comes within `slack` of its line — and kept while the pad's pose relative to
// the body stays within `slack` of the pose they were gathered at (every point of every segment moves less than
// that). The answers are those of a test against every triangle of the mesh: a triangle the segment meets now is
// within `slack` of where the segment was, so it is among the candidates.
//
// The segment–triangle test is watertight (Woop, Benthin and Wald, "Watertight ray/triangle intersection", JCGT
// 2013): a segment through an edge two triangles share meets at least one of them, so nothing slips through a
// closed surface between two triangles.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "collision/aabb.h"
#include "core/math.h"
#include "tactile/pad_elements.h"

namespace graspsim {

// A mesh in its body's frame as the segments meet it: vertices in double (from the float vertices Embree has),
// and per triangle its corners' indices, its box and its outward unit normal.
struct SegmentMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<collision::Aabb> boxes;
  std::vector<Vec3> normals;

  void AddTriangle(const std::array<uint32_t, 3>& corners, const Vec3& normal);
};

// Does the segment o + t ẑ, 0 <= t <= length, meet the triangle (a, b, c)? *t: where. All in a frame the segment
// runs along z in; a triangle whose corners are mapped to it one by one keeps its edges shared with its
// neighbours', so the test stays watertight. A segment in the triangle's plane meets nothing.
inline bool SegmentAlongZMeetsTriangle(const Vec3& o, const Vec3& a, const Vec3& b, const Vec3& c, double length,
                                       double* t) {
  const double ax = a.x() - o.x(), ay = a.y() - o.y(), bx = b.x() - o.x(), by = b.y() - o.y();
  const double cx = c.x() - o.x(), cy = c.y() - o.y();
  // Edge functions: (0, 0) inside the triangle's projection when all three share a sign.
  const double u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
  if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return false;
  const double det = u + v + w;
  if (det == 0) return false;
  const double along = (u * a.z() + v * b.z() + w * c.z()) / det - o.z();
  if (!(along >= 0 && along <= length)) return false;
  *t = along;
  return true;
}

class NearTriangles {
 public:
  // Whether the candidates gathered hold at the pad → body map x -> rotation x + translation.
  bool Covers(const Mat3& rotation, const Vec3& translation) const;

  // Gathers the candidates of every element's segment (from its position along its normal, `length` long, pad
  // frame; `foam` holds them all) at the pad → body map, to hold while every point of the segments stays within
  // `slack` of where it is now. run_ends: the end of each run of elements sharing their normal.
  void Gather(const SegmentMesh& mesh, const std::vector<PadElement>& elements, const std::vector<uint32_t>& run_ends,
              double length, const collision::Aabb& foam, const Mat3& rotation, const Vec3& translation,
              double slack);

  // The triangles any element of run r may meet: their indices into the mesh, and their corners as indices into
  // the run's own copy of their vertices (body frame; copied together, so a step reads them in order and maps
  // each shared vertex once).
  const uint32_t* run_triangles(size_t r) const { return run_triangles_.data() + run_first_[r]; }
  const std::array<uint32_t, 3>* run_corners(size_t r) const { return run_corners_.data() + run_first_[r]; }
  size_t run_vertex_count(size_t r) const { return run_vertex_first_[r + 1] - run_vertex_first_[r]; }
  const Vec3* run_vertices(size_t r) const { return run_vertices_.data() + run_vertex_first_[r]; }

  // The candidates of element e, as positions in its run's triangles (run_triangles), in ascending triangle order.
  const uint32_t* begin(uint32_t e) const { return positions_.data() + first_[e]; }
  const uint32_t* end(uint32_t e) const { return positions_.data() + first_[e + 1]; }

  // Whether no triangle comes within `slack` of element e's base: then while the candidates hold the base stays
  // on the side of the surface it was on when they were gathered (to reach the other it would cross a triangle).
  bool BaseClear(uint32_t e) const { return base_clear_[e] != 0; }

  // Gathers so far (for tests and benchmarks).
  uint64_t gathers() const { return gathers_; }

 private:
  bool valid_ = false;
  Mat3 rotation_ = Mat3::Identity();
  Vec3 translation_ = Vec3::Zero();
  double slack_ = 0, reach_ = 0;  // reach_: the farthest point of the foam from the pad's origin
  std::vector<uint32_t> near_foam_;              // triangles near the whole foam
  std::vector<uint32_t> run_first_, run_triangles_;
  std::vector<std::array<uint32_t, 3>> run_corners_;
  std::vector<uint32_t> run_vertex_first_;
  std::vector<Vec3> run_vertices_;
  std::vector<uint32_t> first_, positions_;
  std::vector<uint32_t> position_of_, vertex_of_;  // scratch: a triangle's or vertex's place in the current run
  std::vector<uint8_t> base_clear_;
  uint64_t gathers_ = 0;
};

}  // namespace graspsim
