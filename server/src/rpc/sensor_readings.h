// TactileService's sensor readings (sensors/sensor_registry.h) as messages.
#pragma once

#include "graspsim/v1/tactile.pb.h"
#include "sensors/readings.h"
#include "sensors/sensor_registry.h"
#include "tactile/tactile_frame.h"

namespace graspsim::rpc {

// The readings as messages: intensities and forces packed little-endian (uint16, float32 x y z per texel).
void ToProto(const TactileFrame& frame, v1::TactileReading* out);
void ToProto(const GripperReading& reading, v1::GripperReading* out);
void ToProto(const ForceTorqueReading& reading, v1::ForceTorqueReading* out);
void ToProto(const SensorReading& reading, v1::SensorReading* out);

}  // namespace graspsim::rpc
