// What GatewayService.PredictAction decides beside its stream, without gRPC (gateway/action_prediction.h): the
// timeout and rate defaults and their refusals naming the field; which samples are reported (at most one per
// 1 / rate_hz of the action's time, the first and the last always); a sample carries `done` once the real
// fingers stopped after moving.
#include "gateway/action_prediction.h"

#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "import/robot_import.h"
#include "test_util.h"
#include "world/loaders.h"
#include "world/scene.h"

namespace graspsim::gateway {
namespace {

using test_util::ExpectError;

TEST(PredictionTiming, ZeroKeepsTheDefaultsAndRangesAreChecked) {
  const PredictionTiming defaults = PredictionTimingFrom(0, 0);
  EXPECT_EQ(defaults.timeout, 5);
  EXPECT_EQ(defaults.rate_hz, 50);
  const PredictionTiming given = PredictionTimingFrom(60, 1000);
  EXPECT_EQ(given.timeout, 60);
  EXPECT_EQ(given.rate_hz, 1000);
  ExpectError([] { PredictionTimingFrom(61, 0); }, ErrorCode::kInvalidArgument, {"timeout: 61", "outside (0, 60]"});
  ExpectError([] { PredictionTimingFrom(-1, 0); }, ErrorCode::kInvalidArgument, {"timeout: -1"});
  ExpectError([] { PredictionTimingFrom(0, 1001); }, ErrorCode::kInvalidArgument, {"rate_hz: 1001", "outside (0, 1000]"});
  ExpectError([] { PredictionTimingFrom(0, NAN); }, ErrorCode::kInvalidArgument, {"rate_hz: nan"});
}

TEST(SampleGate, ReportsAtMostTheRateButAlwaysTheFirstAndTheLast) {
  SampleGate gate(50);  // one per 20 ms of the action's time
  std::vector<double> reported;
  for (int i = 0; i <= 10; ++i) {
    PredictionSample sample;
    sample.time = 0.007 * i;  // a reading every 7 ms
    if (gate.Due(sample)) reported.push_back(sample.time);
  }
  PredictionSample last;
  last.time = 0.071;  // 1 ms after the last reported one, but the action's end
  last.done = true;
  if (gate.Due(last)) reported.push_back(last.time);
  ASSERT_EQ(reported.size(), 5u);
  EXPECT_EQ(reported[0], 0.0);
  for (size_t i = 1; i + 1 < reported.size(); ++i) EXPECT_GE(reported[i] - reported[i - 1], 0.02 - 1e-12);
  EXPECT_EQ(reported.back(), 0.071);
}

TEST(ActionPrediction, NextSaysWhenTheRealFingersStopped) {
  Scene scene("s", "test", Limits{});
  scene.AddRobot("pg", "builtin:schunk_pg70", LoadUrdf(BuiltinModelUrdf("schunk_pg70"), nullptr, Limits()), Pose());
  const SceneView view = scene.View();
  const DeviceLimits limits{.min_opening = 0, .max_opening = 0.070, .min_speed = 0.001, .max_speed = 0.082,
                            .min_force = 1, .max_force = 199.5, .max_current = 3.5};
  DeviceReading start{.device_id = "d", .time = 100, .opening = 0.060};
  ActionPrediction prediction(std::make_unique<SimulatedGripper>(view.model, view.state, "pg"), limits,
                              Move{0.020, 0.040, 100}, start);
  DeviceReading moving = start;
  moving.time = 100.5;
  moving.opening = 0.045;
  moving.moving = true;
  const PredictionSample during = prediction.Next(moving);
  EXPECT_NEAR(during.time, 0.5, 1e-12);
  EXPECT_FALSE(during.done);
  EXPECT_GT(during.surprise, 0);
  DeviceReading stopped = moving;
  stopped.time = 101.5;
  stopped.opening = 0.020;
  stopped.moving = false;
  const PredictionSample end = prediction.Next(stopped);
  EXPECT_TRUE(end.done);
  EXPECT_NEAR(end.measured.opening, 0.020, 0);
}

}  // namespace
}  // namespace graspsim::gateway
