#include "rpc/sensor_readings.h"

#include "rpc/convert.h"
#include "rpc/packed_arrays.h"

namespace graspsim::rpc {

void ToProto(const TactileFrame& frame, v1::TactileReading* out) {
  out->set_rows(frame.rows);
  out->set_cols(frame.cols);
  out->set_intensities(Pack(frame.intensities));
  out->set_forces(PackFloat32Xyz(frame.forces));
  out->set_intensity_sum(frame.intensity_sum);
  ToProto(frame.force_sum, out->mutable_force_sum());
}

void ToProto(const GripperReading& reading, v1::GripperReading* out) {
  out->set_finger_distance(reading.finger_distance);
  out->set_motor_current(reading.motor_current);
  out->set_finger_velocity(reading.finger_velocity);
}

void ToProto(const ForceTorqueReading& reading, v1::ForceTorqueReading* out) {
  ToProto(reading.force, out->mutable_force());
  ToProto(reading.torque, out->mutable_torque());
}

void ToProto(const SensorReading& reading, v1::SensorReading* out) {
  out->set_sensor_id(reading.sensor_id);
  out->set_time(reading.time);
  if (const auto* frame = std::get_if<TactileFrame>(&reading.value)) {
    ToProto(*frame, out->mutable_tactile());
  } else if (const auto* gripper = std::get_if<GripperReading>(&reading.value)) {
    ToProto(*gripper, out->mutable_gripper());
  } else if (const auto* force_torque = std::get_if<ForceTorqueReading>(&reading.value)) {
    ToProto(*force_torque, out->mutable_force_torque());
  }
}

}  // namespace graspsim::rpc
