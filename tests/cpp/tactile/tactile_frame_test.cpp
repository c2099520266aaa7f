// Tactile frames from hand-filled states: texel binning of subdivided pads, the pad-frame transform, intensity
// rounding and saturation, and the heat-map PNG.
#include "tactile/tactile_frame.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tactile/heat_map.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// One static link at `link_pose` carrying one rows × cols pad at `origin`, subdivision s. An object pressing on
// the pad pushes it along the pad's −z (its +z points toward what it touches), so pressing forces below are −z.
struct PadWorld {
  SceneModel model;
  SceneState state;

  PadWorld(unsigned rows, unsigned cols, unsigned s, const Pose& link_pose = {}, const Pose& origin = {}) {
    BodySpec link;
    link.id = "hand/link";
    link.motion = BodyMotion::kStatic;
    model.bodies.push_back(link);
    TactileArraySpec pad;
    pad.id = "hand/pad";
    pad.body_id = link.id;
    pad.origin = origin;
    pad.rows = rows;
    pad.cols = cols;
    pad.pitch = 0.004;
    pad.thickness = 0.004;
    pad.subdivision = s;
    pad.intensity_per_newton = 100;  // round numbers: 0.01 N per count
    model.tactile_arrays.push_back(pad);
    model.Reindex();
    state.body_poses = {link_pose};
    state.pad_forces = {std::vector<Vec3>(size_t{rows} * cols * s * s, Vec3::Zero())};
  }
  // The element at element-grid row r, column c (tactile/pad_elements.h order).
  Vec3& Element(unsigned r, unsigned c) {
    const TactileArraySpec& pad = model.tactile_arrays[0];
    return state.pad_forces[0][size_t{r} * pad.cols * pad.subdivision + c];
  }
  TactileFrame Read() const { return ReadTactileArray(model, state, 0); }
};

size_t Texel(const TactileFrame& frame, unsigned row, unsigned col) { return size_t{row} * frame.cols + col; }

TEST(TactileFrameTest, SubdividedElementsBinIntoTheirTexels) {
  PadWorld world(3, 2, 2);  // element grid 6 × 4
  // The four elements of texel (0, 0), and one element in each of the corner texels (2, 1) and (1, 0).
  for (unsigned r : {0u, 1u}) {
    for (unsigned c : {0u, 1u}) world.Element(r, c) = Vec3(0.01, 0, -0.5);
  }
  world.Element(5, 3) = Vec3(0, 0, -0.25);   // texel (2, 1)
  world.Element(3, 1) = Vec3(0, -0.1, -1.0); // texel (1, 0)
  const TactileFrame frame = world.Read();
  ASSERT_EQ(frame.rows, 3u);
  ASSERT_EQ(frame.cols, 2u);
  ASSERT_EQ(frame.forces.size(), 6u);
  EXPECT_TRUE(frame.forces[Texel(frame, 0, 0)].isApprox(Vec3(0.04, 0, -2.0)));
  EXPECT_TRUE(frame.forces[Texel(frame, 2, 1)].isApprox(Vec3(0, 0, -0.25)));
  EXPECT_TRUE(frame.forces[Texel(frame, 1, 0)].isApprox(Vec3(0, -0.1, -1.0)));
  EXPECT_EQ(frame.intensities[Texel(frame, 0, 0)], 200);
  EXPECT_EQ(frame.intensities[Texel(frame, 2, 1)], 25);
  EXPECT_EQ(frame.intensities[Texel(frame, 1, 0)], 100);
  for (unsigned t : {1u, 3u, 4u}) {
    EXPECT_EQ(frame.intensities[t], 0) << "texel " << t;
    EXPECT_EQ(frame.forces[t], Vec3::Zero()) << "texel " << t;
  }
  EXPECT_EQ(frame.intensity_sum, 325u);
  EXPECT_TRUE(frame.force_sum.isApprox(Vec3(0.04, -0.1, -3.25)));
}

TEST(TactileFrameTest, ForcesAreInThePadFrame) {
  // Link turned 90° about world z, pad turned 90° about the link's x (as the PG70's pads): pad x = world +y,
  // pad y = world +z, pad z = world +x (worked by hand: Rz90 · Rx90 applied to each pad axis).
  const Pose link{Vec3(0.3, -0.2, 1.0), Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()))};
  const Pose origin{Vec3(0, 0.005, 0.03), QuatFromRpy(kPi / 2, 0, 0)};
  PadWorld world(2, 2, 1, link, origin);
  world.Element(1, 0) = Vec3(-1.5, 0.2, -0.3);  // pressing along world −x, i.e. pad −z
  const TactileFrame frame = world.Read();
  const Vec3 pad_force = frame.forces[Texel(frame, 1, 0)];
  EXPECT_NEAR(pad_force.x(), 0.2, 1e-12);
  EXPECT_NEAR(pad_force.y(), -0.3, 1e-12);
  EXPECT_NEAR(pad_force.z(), -1.5, 1e-12);
  EXPECT_EQ(frame.intensities[Texel(frame, 1, 0)], 150);
  EXPECT_TRUE(frame.force_sum.isApprox(pad_force));
}

TEST(TactileFrameTest, IntensityRoundsSaturatesAndIgnoresPulling) {
  PadWorld world(1, 5, 1);
  world.Element(0, 0) = Vec3(0, 0, -0.014);  // 1.4 counts → 1
  world.Element(0, 1) = Vec3(0, 0, -0.016);  // 1.6 → 2
  world.Element(0, 2) = Vec3(0, 0, -50);     // 5000 → the 12-bit maximum
  world.Element(0, 3) = Vec3(0.3, 0, 2);     // along +z the object would pull: no pressure
  world.Element(0, 4) = Vec3(0, 0, -1e300);  // far beyond any integer: still the maximum
  const TactileFrame frame = world.Read();
  EXPECT_EQ(frame.intensities[0], 1);
  EXPECT_EQ(frame.intensities[1], 2);
  EXPECT_EQ(frame.intensities[2], 4095);
  EXPECT_EQ(frame.intensities[3], 0);
  EXPECT_EQ(frame.intensities[4], 4095);
  EXPECT_EQ(frame.forces[3], Vec3(0.3, 0, 2)) << "the force itself is reported as it is";
  EXPECT_EQ(frame.intensity_sum, 1u + 2 + 4095 + 0 + 4095);
}

TEST(TactileFrameTest, MissingOrShortElementForcesReadAsZero) {
  PadWorld world(2, 3, 2);
  world.state.pad_forces.clear();  // a scene that never stepped
  TactileFrame frame = world.Read();
  EXPECT_EQ(frame.intensities, std::vector<uint16_t>(6, 0));
  EXPECT_EQ(frame.intensity_sum, 0u);
  EXPECT_EQ(frame.force_sum, Vec3::Zero());

  world.state.pad_forces = {{Vec3(0, 0, -1), Vec3(0, 0, -1)}};  // only the first two elements: texel (0, 0)
  frame = world.Read();
  EXPECT_EQ(frame.intensities[0], 200);
  EXPECT_EQ(frame.intensity_sum, 200u);
}

TEST(TactileFrameTest, PngHasTheRightSizeAndTheHottestTexelWherePressed) {
  PadWorld world(14, 6, 1);
  world.Element(9, 4) = Vec3(0, 0, -20);  // 2000 counts, about half scale
  world.Element(2, 1) = Vec3(0, 0, -5);   // 500, dimmer
  const TactileFrame frame = world.Read();
  const std::string png = TactileImagePng(frame, 4095, 10);
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));

  const cv::Mat image = cv::imdecode(cv::Mat(1, static_cast<int>(png.size()), CV_8UC1, (void*)png.data()),
                                     cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 60);
  EXPECT_EQ(image.rows, 140);
  cv::Mat gray;
  cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  cv::Point hottest;
  cv::minMaxLoc(gray, nullptr, nullptr, nullptr, &hottest);
  EXPECT_EQ(hottest.x / 10, 4);
  EXPECT_EQ(hottest.y / 10, 9);
  // Every pixel of a texel has its colour (nearest-neighbour), and an untouched texel is black (inferno at 0).
  EXPECT_EQ(gray.at<uint8_t>(90, 40), gray.at<uint8_t>(99, 49));
  EXPECT_LT(gray.at<uint8_t>(0, 0), 5);
  EXPECT_GT(gray.at<uint8_t>(25, 15), gray.at<uint8_t>(0, 0));
  EXPECT_LT(gray.at<uint8_t>(25, 15), gray.at<uint8_t>(95, 45));
}

}  // namespace
}  // namespace graspsim
