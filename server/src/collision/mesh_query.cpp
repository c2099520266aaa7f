// Closest points and inside tests on Embree BVHs of closed triangle meshes (see mesh_query.h).
#include "collision/mesh_query.h"

#include <atomic>
#include <cfloat>
#include <cmath>
#include <limits>
#include <utility>

namespace graspsim::collision {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
constexpr float kUnknown = -1;  // a clearance cell not worked out yet
constexpr int kGridCellsLongest = 48;  // clearance cells along the mesh's longest side

// The parity ray leaves away from the mesh's centre, so that from a point outside a compact mesh it usually
// crosses nothing and from inside crosses once: one or two casts instead of three. The fixed skew added to it
// keeps it off the axes and diagonals, so rays from lattice samples against axis-aligned or 45-degree meshes do
// not run through edges and vertices, where a crossing could be counted twice. It depends only on the point.
const Vec3 kSkew = Vec3(0.29583, 0.54474, 0.78491).normalized();

Vec3 RayDirection(const Vec3& p, const Vec3& centre) {
  const Vec3 away = p - centre;
  const double length = away.norm();
  const Vec3 d = length > 0 ? Vec3(away / length + 0.5 * kSkew) : kSkew;
  return d.squaredNorm() > 1e-6 ? Vec3(d.normalized()) : kSkew;
}

bool VisitTriangle(RTCPointQueryFunctionArguments* args) {
  auto* search = static_cast<ClosestSearch*>(args->userPtr);
  const uint32_t t = args->primID;
  // A degenerate triangle has no normal to give; its closest point is also on a real neighbour.
  if ((*search->normals)[t].isZero()) return false;
  const auto& tri = search->mesh->triangles[t];
  const auto& v = search->mesh->vertices;
  const Vec3 c = ClosestPointOnTriangle(search->p, v[tri[0]].cast<double>(), v[tri[1]].cast<double>(),
                                        v[tri[2]].cast<double>());
  const double d2 = (search->p - c).squaredNorm();
  // Equal distances go to the lower triangle index, so the result does not depend on the traversal order.
  if (d2 < search->best_d2 || (d2 == search->best_d2 && t < search->best_triangle)) {
    search->best_d2 = d2;
    search->best_triangle = t;
    search->best_point = c;
    // Shrink the search, rounded up so that triangles at exactly this distance are still visited.
    args->query->radius = std::nextafter(static_cast<float>(std::sqrt(d2)), kInfinity);
    return true;
  }
  return false;
}

}  // namespace

Vec3 ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;  // vertex region a
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;  // vertex region b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;  // edge ab
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;  // vertex region c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;  // edge ac
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);  // bc
  const double sum = va + vb + vc;
  if (!(sum > 0)) {  // degenerate triangle that slipped through the regions above: its nearest vertex
    const double da = ap.squaredNorm(), db = bp.squaredNorm(), dc = cp.squaredNorm();
    return da <= db && da <= dc ? a : (db <= dc ? b : c);
  }
  return a + (vb / sum) * ab + (vc / sum) * ac;  // inside the face, barycentric (u, v, w)
}

// Medium (Embree's default) build quality: a BVH is built for every model a scene's edits make, so building
// counts as much as querying.
MeshBvh::MeshBvh(std::shared_ptr<const TriangleMesh> shared)
    : mesh_(std::move(shared)), scene_(*mesh_, RTC_BUILD_QUALITY_MEDIUM) {
  const TriangleMesh& mesh = *mesh_;
  double extent = 0;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& v : mesh.vertices) {
    const Vec3 p = v.cast<double>();
    extent = std::max(extent, p.cwiseAbs().maxCoeff());
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  centre_ = 0.5 * (lo + hi);
  normals_.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]].cast<double>();
    const Vec3 n = (mesh.vertices[t[1]].cast<double>() - a).cross(mesh.vertices[t[2]].cast<double>() - a);
    const double length = n.norm();
    normals_.push_back(length > 0 ? Vec3(n / length) : Vec3::Zero());
  }
  // The ray starts at p rounded to float and Embree intersects in float: a few float ulps of the coordinates.
  near_surface_ = 8 * FLT_EPSILON * std::max(extent, 1e-3);
  // The clearance grid covers the bounding box (a point outside it needs no grid: the caller's bounds cull it).
  cell_size_ = std::max((hi - lo).maxCoeff() / kGridCellsLongest, 1e-4);
  grid_origin_ = lo;
  grid_cells_ = ((hi - lo) / cell_size_).array().ceil().cast<int>().cwiseMax(1);
  clearance_ = std::make_unique<std::atomic<float>[]>(static_cast<size_t>(grid_cells_.prod()));
  for (int64_t i = 0; i < grid_cells_.prod(); ++i) clearance_[i].store(kUnknown, std::memory_order_relaxed);
}

int MeshBvh::Crossings(const Vec3& p, float* first_hit) const {
  // Count the surface crossings of a ray from p. Each cast returns the nearest hit beyond tnear; restarting just
  // past it walks through all crossings (two triangles hit at the same t, the ray passing through their shared
  // edge, count once).
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit ray_hit;
  SetRay(&ray_hit, p, RayDirection(p, centre_), kInfinity, 0);
  RTCRay& ray = ray_hit.ray;
  int crossings = 0;
  *first_hit = kInfinity;
  for (;;) {
    ray.tfar = kInfinity;
    ray_hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    ray_hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_.handle(), &context, &ray_hit);
    if (ray_hit.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
    if (crossings++ == 0) *first_hit = ray.tfar;
    ray.tnear = std::nextafter(ray.tfar, kInfinity);
  }
  return crossings;
}

// The closest surface point within `radius` of p (best_triangle unset when none).
ClosestSearch MeshBvh::Closest(const Vec3& p, float radius) const {
  RTCPointQuery query;
  query.x = static_cast<float>(p.x());
  query.y = static_cast<float>(p.y());
  query.z = static_cast<float>(p.z());
  query.time = 0;
  query.radius = radius;
  RTCPointQueryContext query_context;
  rtcInitPointQueryContext(&query_context);
  ClosestSearch search{mesh_.get(), &normals_, p, static_cast<double>(radius) * radius};
  rtcPointQuery(scene_.handle(), &query, &query_context, VisitTriangle, &search);
  return search;
}

double MeshBvh::Clearance(const Vec3& p) const {
  // A cell of the grid whose centre lies outside, farther from the surface than the cell's half-diagonal, lies
  // outside whole, each of its points at least (that distance − the half-diagonal) from the surface: such a
  // point can be answered "outside, that far at least" without a ray. Worked out on a cell's first query (the
  // same answer whichever thread writes it) and kept, so the cells around a body's resting place cost one query
  // each, once. kUnknown: not yet; ≤ 0: no bound (inside, or near the surface).
  const Eigen::Vector3i cell = ((p - grid_origin_) / cell_size_).array().floor().cast<int>();
  if ((cell.array() < 0).any() || (cell.array() >= grid_cells_.array()).any()) return 0;
  std::atomic<float>& slot = clearance_[(cell.z() * grid_cells_.y() + cell.y()) * grid_cells_.x() + cell.x()];
  float known = slot.load(std::memory_order_relaxed);
  if (known != kUnknown) return known;
  const Vec3 centre = grid_origin_ + (cell.cast<double>() + Vec3::Constant(0.5)) * cell_size_;
  const double half_diagonal = 0.5 * std::sqrt(3.0) * cell_size_, reach = 4 * half_diagonal;
  float first_hit = 0;
  if (Crossings(centre, &first_hit) % 2 == 1) {
    known = 0;
  } else {
    const ClosestSearch search = Closest(centre, static_cast<float>(reach));
    const double distance = search.best_triangle == std::numeric_limits<uint32_t>::max() ? reach
                                                                                           : std::sqrt(search.best_d2);
    // Parity is trusted only away from the surface (float noise): the bound must also clear near_surface_.
    known = static_cast<float>(std::max(0.0, distance - half_diagonal - near_surface_));
  }
  slot.store(known, std::memory_order_relaxed);
  return known;
}

bool MeshBvh::Depth(const Vec3& p, double margin, double* depth, Vec3* normal) const {
  if (Clearance(p) > std::max(margin, near_surface_)) return false;  // outside, beyond the margin
  float first_hit = kInfinity;
  bool inside = Crossings(p, &first_hit) % 2 == 1;
  if (!inside && margin <= 0) return false;

  // Closest surface point. Inside, the first crossing bounds the distance; outside only `margin` matters.
  // The slack covers p's rounding to float for the query centre.
  const float radius = static_cast<float>((inside ? first_hit * (1 + 1e-6) : margin) + near_surface_);
  const ClosestSearch search = Closest(p, radius);
  if (search.best_triangle == std::numeric_limits<uint32_t>::max()) return false;

  const double distance = std::sqrt(search.best_d2);
  const Vec3& face_normal = normals_[search.best_triangle];
  // Within float noise of the surface the ray may start on the wrong side; the closest face's orientation
  // (counter-clockwise outward) decides there.
  if (distance < near_surface_) inside = (p - search.best_point).dot(face_normal) < 0;
  if (!inside && !(distance < margin)) return false;
  *depth = inside ? distance : -distance;
  *normal = face_normal;
  return true;
}

}  // namespace graspsim::collision
