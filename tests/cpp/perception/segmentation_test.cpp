// Table-top segmentation (perception/segmentation.h): a 60 × 60 cm table sampled every 5 mm with 1 mm noise and
// three boxes on it 12 cm apart. RANSAC must find the table (normal within 1°, offset within 2 mm) and Euclidean
// clustering exactly the three boxes, each with every one of its points.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "perception/segmentation.h"

namespace graspsim {
namespace {

// The faces of an axis-aligned box above the table (bottom face omitted: it sits on the table), every 4 mm.
std::vector<Vec3> BoxAbove(const Vec3& centre, const Vec3& size) {
  std::vector<Vec3> out;
  const double s = 0.004;
  for (double x = -size.x() / 2; x <= size.x() / 2 + 1e-9; x += s) {
    for (double y = -size.y() / 2; y <= size.y() / 2 + 1e-9; y += s) out.push_back(centre + Vec3(x, y, size.z() / 2));
    for (double z = -size.z() / 2 + 0.015; z <= size.z() / 2 + 1e-9; z += s) {
      out.push_back(centre + Vec3(x, -size.y() / 2, z));
      out.push_back(centre + Vec3(x, size.y() / 2, z));
    }
  }
  return out;
}

TEST(SegmentationTest, FindsTheTableAndEachObject) {
  std::mt19937 random(5);
  std::normal_distribution<double> noise(0, 0.001);
  const double tilt = 0.05;  // the table's normal 0.05 rad off z, about x
  const Vec3 normal(0, -std::sin(tilt), std::cos(tilt));
  const Quat tilt_q(Eigen::AngleAxisd(tilt, Vec3::UnitX()));
  std::vector<Vec3> cloud;
  for (double x = -0.3; x <= 0.3; x += 0.005) {
    for (double y = -0.3; y <= 0.3; y += 0.005) cloud.push_back(tilt_q * Vec3(x, y, 0.7 + noise(random)));
  }
  const std::vector<Vec3> centres = {{-0.15, 0, 0.7 + 0.04}, {0, 0.05, 0.7 + 0.05}, {0.15, -0.05, 0.7 + 0.03}};
  const std::vector<Vec3> sizes = {{0.06, 0.06, 0.08}, {0.05, 0.09, 0.10}, {0.07, 0.04, 0.06}};
  std::vector<size_t> counts;
  for (size_t b = 0; b < centres.size(); ++b) {
    std::vector<Vec3> box = BoxAbove(centres[b], sizes[b]);
    for (Vec3& p : box) cloud.push_back(tilt_q * p);
    counts.push_back(box.size());
  }
  const SceneSegmentation seg = SegmentScene(cloud, {});
  EXPECT_LT(std::acos(std::min(1.0, seg.table_normal.dot(normal))), M_PI / 180);
  EXPECT_NEAR(seg.table_offset, 0.7, 0.002);
  ASSERT_EQ(seg.objects.size(), 3u);
  std::vector<size_t> found;
  for (const auto& object : seg.objects) found.push_back(object.size());
  std::sort(counts.rbegin(), counts.rend());
  EXPECT_EQ(found, counts);
  // Deterministic: the same answer again.
  const SceneSegmentation again = SegmentScene(cloud, {});
  EXPECT_EQ(again.table_normal, seg.table_normal);
  EXPECT_EQ(again.objects, seg.objects);
}

TEST(SegmentationTest, RejectsAnEmptyCloudAndBadTolerance) {
  EXPECT_THROW(SegmentScene({}, {}), Error);
  SegmentationParams params;
  params.cluster_tolerance = -1;
  try {
    SegmentScene({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, params);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cluster_tolerance: -1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace graspsim
