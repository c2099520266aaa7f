// Tactile pads on all three engines (physics/engine.h, physics/pad_readout.h): a load resting on a pad facing up
// reads m g on every engine, under its own footprint only, centred where it rests: closed forms, not the
// engines' own formulas.
#include <cmath>

#include <gtest/gtest.h>

#include "physics/engine.h"
#include "physics/pad_stand.h"
#include "tactile/tactile_frame.h"

namespace graspsim {
namespace {

constexpr double kG = 9.81;

class PadEnginesTest : public ::testing::TestWithParam<PhysicsEngineKind> {
 protected:
  // The DSA 9205-like stand pad (14 × 6 texels at 3.4 mm, 4 mm of foam) facing up, and `body` resting on it at
  // (x, y), its lowest point `bottom` below its origin.
  void Start(BodySpec body, double x, double y, double bottom, unsigned subdivision = 1) {
    model_->simulation.engine = GetParam();
    model_->simulation.sleep_time = 0;
    test_objects::AddPadStand(model_.get(), test_objects::StandPad(subdivision));
    model_->bodies.push_back(std::move(body));
    model_->Reindex();
    state_.body_poses = {Pose(), {Vec3(x, y, 0.004 + bottom), Quat::Identity()}};
    engine_ = MakePhysicsEngine(model_);
    engine_->PrepareState(&state_);
    engine_->Step(&state_, 1000);  // 1 s at 1 ms: at rest
  }
  TactileFrame Frame() const { return ReadTactileArray(*model_, state_, 0); }

  std::shared_ptr<SceneModel> model_ = std::make_shared<SceneModel>();
  SceneState state_;
  std::shared_ptr<PhysicsEngine> engine_;
};

// The pad frame's texel (row, col) centre: rows along y, cols along x, both from the pad's centre.
Vec3 TexelCentre(unsigned row, unsigned col) {
  return Vec3((col + 0.5) * 0.0034 - 3 * 0.0034, (row + 0.5) * 0.0034 - 7 * 0.0034, 0);
}

TEST_P(PadEnginesTest, ABoxCoveringThePadIsCarriedEvenlyByEveryTexel) {
  // 0.2 kg, 3 × 6 cm: the pad (2.04 × 4.76 cm) lies under it whole. Σ = m g within 1 %; every texel loaded,
  // each within 5 % of m g / 84 (a face lying flat presses every element alike).
  Start(test_objects::UniformBox("box", Vec3(0.03, 0.06, 0.02), 0.2), 0, 0, 0.01);
  const TactileFrame frame = Frame();
  EXPECT_NEAR(-frame.force_sum.z() / (0.2 * kG), 1.0, 0.01) << EngineName(GetParam());
  for (const Vec3& texel : frame.forces) EXPECT_NEAR(-texel.z() / (0.2 * kG / 84), 1.0, 0.05);
}

TEST_P(PadEnginesTest, ASmallBoxIsReadUnderItsFootprintAtItsPlace) {
  // A 1.2 cm cube of 30 g resting off-centre at (−3.4, +5.1) mm: the loaded texels are those whose centres lie
  // under its face (up to half a texel's slack at the face's edge, where the foam law shares a texel), the centre
  // of pressure is the cube's centre within 0.5 mm, and Σ = m g within 1 %; moved, it is read at its new place.
  const double x = -0.0034, y = 0.0051, half = 0.006;
  Start(test_objects::UniformBox("cube", Vec3(2 * half, 2 * half, 2 * half), 0.03), x, y, half);
  const TactileFrame frame = Frame();
  EXPECT_NEAR(-frame.force_sum.z() / (0.03 * kG), 1.0, 0.01) << EngineName(GetParam());
  Vec3 moment = Vec3::Zero();
  for (unsigned r = 0; r < 14; ++r) {
    for (unsigned c = 0; c < 6; ++c) {
      const Vec3 centre = TexelCentre(r, c);
      const double load = -frame.forces[r * 6 + c].z();
      const double outside = std::max(std::abs(centre.x() - x), std::abs(centre.y() - y)) - half;
      if (outside < -0.0017) {
        EXPECT_GT(load, 0) << "texel " << r << "," << c << " under the cube";
      }
      if (outside > 0.0017) {
        EXPECT_EQ(load, 0) << "texel " << r << "," << c << " beside the cube";
      }
      moment += load * centre;
    }
  }
  const Vec3 pressure_centre = moment / -frame.force_sum.z();
  EXPECT_NEAR(pressure_centre.x(), x, 5e-4);
  EXPECT_NEAR(pressure_centre.y(), y, 5e-4);

  // Moved to the pad's other end (a SetBodyPoses), the cube is read there only: nothing stays of the old place.
  state_.body_poses[1].position = Vec3(x, -y - 0.0102, state_.body_poses[1].position.z());
  engine_->Step(&state_, 200);
  const TactileFrame moved = Frame();
  EXPECT_NEAR(-moved.force_sum.z() / (0.03 * kG), 1.0, 0.01);
  for (unsigned r = 7; r < 10; ++r) {
    for (unsigned c = 0; c < 4; ++c) EXPECT_EQ(moved.forces[r * 6 + c].z(), 0) << "texel " << r << "," << c;
  }
}

TEST_P(PadEnginesTest, ASphereIsReadAroundTheTexelItRestsOn) {
  // A 2 cm ball of 150 g resting over texel (6, 2)'s centre, 2 × 2 elements per texel: the most loaded texel is
  // that one, its four neighbours carry a part (the foam law spreads the load), alike within 2 %, and Σ = m g
  // within 1 %.
  BodySpec ball;
  ball.id = "ball";
  Geometry sphere;
  sphere.kind = Geometry::Kind::kSphere;
  sphere.radius = 0.01;
  ball.collision.push_back(sphere);
  ball.inertial.mass = 0.15;
  ball.inertial.inertia = Mat3::Identity() * (0.4 * 0.15 * 1e-4);
  const Vec3 at = TexelCentre(6, 2);
  Start(ball, at.x(), at.y(), 0.01, 2);
  const TactileFrame frame = Frame();
  EXPECT_NEAR(-frame.force_sum.z() / (0.15 * kG), 1.0, 0.01) << EngineName(GetParam());
  auto load = [&](unsigned r, unsigned c) { return -frame.forces[r * 6 + c].z(); };
  for (unsigned i = 0; i < 84; ++i) EXPECT_LE(-frame.forces[i].z(), load(6, 2)) << "texel " << i;
  EXPECT_GT(load(5, 2), 0.01 * load(6, 2));
  for (double neighbour : {load(7, 2), load(6, 1), load(6, 3)}) EXPECT_NEAR(neighbour, load(5, 2), 0.02 * load(6, 2));
  EXPECT_EQ(load(0, 0), 0);
}

INSTANTIATE_TEST_SUITE_P(Engines, PadEnginesTest,
                         ::testing::Values(PhysicsEngineKind::kGraspsim, PhysicsEngineKind::kMujoco,
                                           PhysicsEngineKind::kBullet),
                         [](const auto& info) { return EngineName(info.param); });

}  // namespace
}  // namespace graspsim
