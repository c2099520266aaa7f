// The gripper's and the force/torque sensors' readings (see readings.h).
#include "sensors/readings.h"

#include <algorithm>
#include <string>
#include <vector>

#include "core/error.h"

namespace graspsim {
namespace {

// A finger is a prismatic joint with no prismatic joint below it: a linear axis that carries the gripper (the
// z axis of "schunk_pg70_on_z_axis") is not one.
bool IsFinger(const SceneModel& model, const RobotSpec& robot, const JointSpec& joint) {
  if (joint.type != JointType::kPrismatic) return false;
  std::vector<std::string> below = {joint.child_body};  // bodies in the joint's subtree
  for (const std::string& id : robot.joint_ids) {  // topological order: parents before children
    const JointSpec& other = model.joints[model.joint_index.at(id)];
    if (std::find(below.begin(), below.end(), other.parent_body) == below.end()) continue;
    if (other.type == JointType::kPrismatic) return false;
    below.push_back(other.child_body);
  }
  return true;
}

}  // namespace

GripperReading ReadGripper(const SceneModel& model, const SceneState& state, const RobotSpec& robot) {
  GripperReading reading;
  bool have_driver = false;
  for (const std::string& id : robot.joint_ids) {
    const size_t index = model.joint_index.at(id);
    const JointSpec& joint = model.joints[index];
    if (!IsFinger(model, robot, joint)) continue;
    if (index < state.joint_positions.size()) reading.finger_distance += state.joint_positions[index];
    // The first independent finger is the one the motor drives; mimic fingers follow it.
    if (have_driver || joint.mimic) continue;
    have_driver = true;
    if (index < state.joint_velocities.size()) reading.finger_velocity = state.joint_velocities[index];
    if (const auto actuator = state.actuators.find(index); actuator != state.actuators.end()) {
      reading.motor_current = actuator->second.state.current;
    }
  }
  return reading;
}

ForceTorqueReading ReadForceTorque(const SceneModel& model, const SceneState& state, size_t joint) {
  const JointSpec& spec = model.joints.at(joint);
  // Joint wrenches come from graspsim's recursive Newton–Euler with its contact forces; another engine's step
  // leaves them at zero, which would read as an unloaded sensor.
  if (model.simulation.engine != PhysicsEngineKind::kGraspsim) {
    throw Error(ErrorCode::kFailedPrecondition, "sensor '" + spec.id +
                                                    "': force/torque sensors need the graspsim engine (the scene "
                                                    "runs on another; SimulationParams.engine)");
  }
  ForceTorqueReading reading;
  // The simulation sizes joint_wrenches only once it has stepped: a scene that never ran reads zero.
  if (joint < state.joint_wrenches.size()) {
    reading.force = state.joint_wrenches[joint][0];
    reading.torque = state.joint_wrenches[joint][1];
  }
  return reading;
}

}  // namespace graspsim
