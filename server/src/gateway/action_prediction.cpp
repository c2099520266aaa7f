#include "gateway/action_prediction.h"

#include <cmath>
#include <string>

#include "core/error.h"

namespace graspsim::gateway {
namespace {

constexpr double kAtTarget = 1e-3;  // m: a finished move is this close to its target (the devices' resolution)

}  // namespace

double Surprise(const GripperSample& predicted, const GripperSample& measured, const DeviceLimits& limits) {
  const double opening = (predicted.opening - measured.opening) / limits.max_opening;
  const double current = (predicted.current - measured.current) / limits.max_current;
  return std::sqrt((opening * opening + current * current) / 2);
}

PredictionTiming PredictionTimingFrom(double timeout, double rate_hz) {
  PredictionTiming timing;
  if (timeout != 0) timing.timeout = timeout;
  if (!(timing.timeout > 0 && timing.timeout <= 60)) {
    ThrowInvalidArgument("timeout: " + std::to_string(timeout) + " s is outside (0, 60]");
  }
  if (rate_hz != 0) timing.rate_hz = rate_hz;
  if (!(timing.rate_hz > 0 && timing.rate_hz <= 1000)) {
    ThrowInvalidArgument("rate_hz: " + std::to_string(rate_hz) + " is outside (0, 1000]");
  }
  return timing;
}

bool SampleGate::Due(const PredictionSample& sample) {
  if (!(sample.done || sample.time == 0 || sample.time >= next_time_)) return false;
  next_time_ = sample.time + interval_;
  return true;
}

ActionPrediction::ActionPrediction(std::unique_ptr<SimulatedGripper> twin, const DeviceLimits& limits,
                                   const Move& move, const DeviceReading& start)
    : twin_(std::move(twin)), limits_(limits), move_(move), start_time_(start.time) {
  twin_->SetOpening(start.opening);
  twin_->MoveTo(move.opening, move.speed, move.force);
}

PredictionSample ActionPrediction::Sample(const DeviceReading& measured) {
  PredictionSample sample;
  sample.time = std::max(0.0, measured.time - start_time_);
  twin_->AdvanceTo(sample.time);
  const drivers::GripperReading predicted = twin_->Read();
  sample.predicted = {predicted.opening_m, predicted.current_a, twin_->TactileSum()};
  sample.measured = {measured.opening, measured.current, 0};
  sample.surprise = Surprise(sample.predicted, sample.measured, limits_);
  return sample;
}

bool ActionPrediction::Finished(const DeviceReading& measured) {
  if (measured.moving) {
    seen_moving_ = true;
    return false;
  }
  return seen_moving_ || measured.object_detected || !measured.fault.empty() ||
         std::abs(measured.opening - move_.opening) < kAtTarget;
}

PredictionSample ActionPrediction::Next(const DeviceReading& measured) {
  PredictionSample sample = Sample(measured);
  sample.done = Finished(measured);
  return sample;
}

}  // namespace graspsim::gateway
