// The simulated PG70 behind GripperDevice and the surprise between prediction and measurement.
#include "gateway/action_prediction.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
#include "import/robot_import.h"
#include "world/loaders.h"
#include "world/scene.h"

namespace graspsim::gateway {
namespace {

const DeviceLimits kPg70{.min_opening = 0, .max_opening = 0.070, .min_speed = 0.001, .max_speed = 0.082,
                         .min_force = 1, .max_force = 199.5, .max_current = 3.5};

TEST(Surprise, IsTheNormalisedRmsDifference) {
  EXPECT_EQ(Surprise({0.03, 1.0, 0}, {0.03, 1.0, 500}, kPg70), 0.0);  // tactile sums do not enter
  // Off by the whole opening range only: sqrt(1/2).
  EXPECT_NEAR(Surprise({0.07, 0, 0}, {0.0, 0, 0}, kPg70), std::sqrt(0.5), 1e-12);
  // 7 mm (0.1 of the range) and 0.35 A (0.1 of the current): sqrt((0.01 + 0.01) / 2) = 0.1.
  EXPECT_NEAR(Surprise({0.037, 0.35, 0}, {0.030, 0.0, 0}, kPg70), 0.1, 1e-12);
}

TEST(SimulatedGripper, MovesAtTheCommandedSpeedAndStopsAtTheTarget) {
  Scene scene("s", "test", Limits{});
  scene.AddRobot("pg", "builtin:schunk_pg70",
                 LoadUrdf(BuiltinModelUrdf("schunk_pg70"), [](const std::string&) { return nullptr; }, Limits()),
                 Pose());
  SceneView view = scene.View();
  SimulatedGripper twin(view.model, view.state, "pg");
  twin.SetOpening(0.060);
  EXPECT_NEAR(twin.Read().opening_m, 0.060, 1e-12);
  twin.MoveTo(0.020, 0.040, 100);  // 40 mm at 40 mm/s: about 1 s
  twin.AdvanceTo(0.5);
  const double halfway = twin.Read().opening_m;
  // 0.5 s at up to 40 mm/s of opening (20 mm/s per finger), less the acceleration: 18..20 mm closed.
  EXPECT_GT(0.060 - halfway, 0.016);
  EXPECT_LE(0.060 - halfway, 0.020 + 1e-4);
  EXPECT_TRUE(twin.Read().moving);
  twin.AdvanceTo(2.0);
  EXPECT_NEAR(twin.Read().opening_m, 0.020, 5e-4);
  EXPECT_FALSE(twin.Read().moving);
  EXPECT_EQ(twin.TactileSum(), 0);  // nothing between the fingers
  EXPECT_NEAR(twin.time(), 2.0, 1e-9);
}

TEST(SimulatedGripper, RefusesARobotWithoutPg70Fingers) {
  Scene scene("s", "test", Limits{});
  SceneView view = scene.View();
  EXPECT_THROW(SimulatedGripper(view.model, view.state, "nope"), Error);
}

}  // namespace
}  // namespace graspsim::gateway
