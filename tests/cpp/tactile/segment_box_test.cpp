// SegmentEntries, the pads' slab test over a run of elements, against its scalar form SegmentMeetsBox: the same
// entry bit for bit, and the same misses, for tilted and axis-aligned directions (zero components take the
// parallel-slab branch), bases inside, outside and on the box's faces.
#include "tactile/segment_box.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace graspsim {
namespace {

// The scalar form as the ray caster used it per element: o = R p + t (Eigen's lazy product), then the slab test.
void ExpectSameAsScalar(const std::vector<Vec3>& points, const Mat3& rotation, const Vec3& translation,
                        const Vec3& d, double length, const collision::Aabb& box, int* hits) {
  std::vector<double> x, y, z;
  for (const Vec3& p : points) x.push_back(p.x()), y.push_back(p.y()), z.push_back(p.z());
  SegmentDirection direction;
  direction.Set(d);
  std::vector<double> entries(points.size(), -1);
  SegmentEntries({x.data(), y.data(), z.data()}, points.size(), rotation, translation, direction, length, box,
                 entries.data());
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3 o = rotation.lazyProduct(points[i]) + translation;
    double entry = -1;
    if (SegmentMeetsBox(o, direction, length, box, &entry)) {
      EXPECT_EQ(entries[i], entry) << "element " << i;  // bit for bit, not within a tolerance
      ++*hits;
    } else {
      EXPECT_EQ(entries[i], std::numeric_limits<double>::infinity()) << "element " << i;
    }
  }
}

TEST(SegmentBox, RunMatchesScalarSlabTestForTiltedDirections) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int hits = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Mat3 rotation = Quat(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    const Vec3 translation(0.02 * u(rng), 0.02 * u(rng), 0.02 * u(rng));
    collision::Aabb box;
    box.lo = Vec3(-0.025, -0.02, -0.03) + 0.005 * Vec3(u(rng), u(rng), u(rng));
    box.hi = -box.lo;
    std::vector<Vec3> points;
    for (int i = 0; i < 37; ++i) points.emplace_back(0.03 * u(rng), 0.03 * u(rng), 0.03 * u(rng));
    const Vec3 d = Vec3(u(rng), u(rng), u(rng)).normalized();
    ExpectSameAsScalar(points, rotation, translation, d, 0.004 + 0.02 * (u(rng) + 1), box, &hits);
  }
  EXPECT_GT(hits, 100);  // the comparison covered hits, not only misses
}

TEST(SegmentBox, RunMatchesScalarSlabTestAlongAxesAndOnFaces) {
  // A flat 6 × 14 pad facing a box's face along +z, +x and a diagonal in the x–y plane (zero components), its grid
  // reaching past the box's edges, its bases in front, on and inside the face.
  collision::Aabb box;
  box.lo = Vec3(-0.02, -0.01, 0.002);
  box.hi = Vec3(0.02, 0.01, 0.05);
  std::vector<Vec3> points;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 14; ++c) points.emplace_back(-0.0221 + 0.0034 * c, -0.0085 + 0.0034 * r, 0);
  }
  int hits = 0;
  for (const double z : {0.0, 0.002, 0.003, -0.003}) {
    for (const Vec3& d : {Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(std::sqrt(0.5), std::sqrt(0.5), 0)}) {
      ExpectSameAsScalar(points, Mat3::Identity(), Vec3(0, 0, z), d, 0.004, box, &hits);
    }
  }
  EXPECT_GT(hits, 100);
}

}  // namespace
}  // namespace graspsim
