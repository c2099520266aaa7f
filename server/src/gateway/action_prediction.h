// Prediction and surprise (PAPERS.md part B's "the simulator predicts the readings a real action will produce"):
// while a real gripper runs one action, its simulated twin (SimulatedGripper) runs the same action from the same
// start opening, stepped to the time of each real reading, and each pair of readings gets a surprise
//   s = sqrt( ((o_p − o_m) / O)² / 2 + ((i_p − i_m) / I)² / 2 )
// with o the opening, i the motor current, O the device's max_opening and I its max_current: 0 when the real
// device does what the model predicts, 1 when it is off by a whole range in both. The tactile sum is predicted
// only (the real devices behind the gateway have no pads) and does not enter s.
#pragma once

#include <memory>

#include "gateway/gateway_types.h"
#include "gateway/simulated_gripper.h"

namespace graspsim::gateway {

struct GripperSample {
  double opening = 0;      // m
  double current = 0;      // A
  double tactile_sum = 0;  // intensity counts, 0 without pads
};

struct PredictionSample {
  double time = 0;  // s since the action began
  GripperSample predicted, measured;
  double surprise = 0;
  bool done = false;
};

double Surprise(const GripperSample& predicted, const GripperSample& measured, const DeviceLimits& limits);

// How long a prediction may wait for the real fingers to stop, and how often it reports (PredictAction).
struct PredictionTiming {
  double timeout = 5;   // s of wall time, (0, 60]
  double rate_hz = 50;  // samples per second of the action's time at most, (0, 1000]
};
// 0 keeps a default; a value outside its range is Error(kInvalidArgument) naming "timeout" or "rate_hz".
PredictionTiming PredictionTimingFrom(double timeout, double rate_hz);

// Which samples a prediction reports: at most one per 1 / rate_hz of the action's time, the first (time 0) and
// the last (done) always.
class SampleGate {
 public:
  explicit SampleGate(double rate_hz) : interval_(1.0 / rate_hz) {}
  bool Due(const PredictionSample& sample);

 private:
  double interval_, next_time_ = 0;
};

class ActionPrediction {
 public:
  // Puts the twin at the start reading's opening and starts `move` on it; `start.time` is the action's time 0.
  ActionPrediction(std::unique_ptr<SimulatedGripper> twin, const DeviceLimits& limits, const Move& move,
                   const DeviceReading& start);
  // The twin stepped to `measured`'s time, beside it.
  PredictionSample Sample(const DeviceReading& measured);
  // The real action is over: not moving after it started (or at the target), or stopped on an object.
  bool Finished(const DeviceReading& measured);
  // Sample, with `done` set when the reading is the action's last (Finished).
  PredictionSample Next(const DeviceReading& measured);
  double start_time() const { return start_time_; }

 private:
  std::unique_ptr<SimulatedGripper> twin_;
  DeviceLimits limits_;
  Move move_;
  double start_time_;
  bool seen_moving_ = false;
};

}  // namespace graspsim::gateway
