#include "persistence/state_codec.h"

#include "core/bytes.h"
#include "core/error.h"

namespace graspsim::persistence {
namespace {

// "GSS" + format. Bumped when the layout changes; a state of another format is refused at start, not misread.
constexpr uint32_t kMagic = 0x01535347;

// The actuator records are packed as they are in memory: a field added to them must be added here too, which
// these assertions make impossible to forget.
static_assert(sizeof(DcMotorParams) == 11 * sizeof(double));
static_assert(sizeof(ActuatorCommand) == 3 * sizeof(double));
static_assert(sizeof(DcMotorState) == 2 * sizeof(double));
static_assert(sizeof(JointActuator) == sizeof(DcMotorParams) + sizeof(ActuatorCommand) + sizeof(DcMotorState) +
                                           2 * sizeof(double));

void PutPose(ByteWriter& w, const Pose& pose) {
  w.Put(pose.position);
  for (double v : {pose.orientation.w(), pose.orientation.x(), pose.orientation.y(), pose.orientation.z()}) w.Put(v);
}

Pose GetPose(ByteReader& r) {
  Pose pose;
  pose.position = r.GetVec3();
  const double w = r.Get<double>(), x = r.Get<double>(), y = r.Get<double>(), z = r.Get<double>();
  pose.orientation = Quat(w, x, y, z);
  return pose;
}

}  // namespace

std::string EncodeState(const SceneState& s) {
  ByteWriter w;
  w.Put(kMagic);
  w.Put(s.time);
  w.Put(s.step);
  w.Put<uint64_t>(s.body_poses.size());
  for (const Pose& pose : s.body_poses) PutPose(w, pose);
  w.Put<uint64_t>(s.joint_positions.size());
  for (double q : s.joint_positions) w.Put(q);
  w.Put<uint64_t>(s.body_velocities.size());
  for (const BodyVelocity& v : s.body_velocities) {
    w.Put(v.linear);
    w.Put(v.angular);
  }
  w.Put<uint64_t>(s.joint_velocities.size());
  for (double v : s.joint_velocities) w.Put(v);
  w.Put<uint64_t>(s.sleeping.size());
  for (bool b : s.sleeping) w.Put<uint8_t>(b ? 1 : 0);
  w.Put<uint64_t>(s.rest_time.size());
  for (double t : s.rest_time) w.Put(t);
  w.Put<uint64_t>(s.bristles.size());
  for (const auto& [key, z] : s.bristles) {
    w.Put(key.body_a);
    w.Put(key.body_b);
    w.Put(key.feature);
    w.Put(z);
  }
  w.Put<uint64_t>(s.actuators.size());
  for (const auto& [joint, actuator] : s.actuators) {
    w.Put<uint64_t>(joint);
    w.Put(actuator);
  }
  w.Put<uint64_t>(s.pad_forces.size());
  for (const auto& pad : s.pad_forces) {
    w.Put<uint64_t>(pad.size());
    for (const Vec3& f : pad) w.Put(f);
  }
  w.Put<uint64_t>(s.joint_wrenches.size());
  for (const auto& wrench : s.joint_wrenches) {
    w.Put(wrench[0]);
    w.Put(wrench[1]);
  }
  w.Put<uint64_t>(s.contacts.size());
  for (const auto& c : s.contacts) {
    w.Put(c.body_a);
    w.Put(c.body_b);
    w.Put(c.point);
    w.Put(c.force);
  }
  return w.Take();
}

SceneState DecodeState(const std::string& bytes, const std::string& what) {
  ByteReader r(bytes.data(), bytes.size(), what);
  if (r.Get<uint32_t>() != kMagic) throw Error(ErrorCode::kInternal, what + ": not a scene state of this format");
  SceneState s;
  s.time = r.Get<double>();
  s.step = r.Get<uint64_t>();
  s.body_poses.resize(r.GetCount(56));
  for (Pose& pose : s.body_poses) pose = GetPose(r);
  s.joint_positions.resize(r.GetCount(8));
  for (double& q : s.joint_positions) q = r.Get<double>();
  s.body_velocities.resize(r.GetCount(48));
  for (BodyVelocity& v : s.body_velocities) {
    v.linear = r.GetVec3();
    v.angular = r.GetVec3();
  }
  s.joint_velocities.resize(r.GetCount(8));
  for (double& v : s.joint_velocities) v = r.Get<double>();
  s.sleeping.resize(r.GetCount(1));
  for (size_t i = 0; i < s.sleeping.size(); ++i) s.sleeping[i] = r.Get<uint8_t>() != 0;
  s.rest_time.resize(r.GetCount(8));
  for (double& t : s.rest_time) t = r.Get<double>();
  s.bristles.resize(r.GetCount(40));
  for (auto& [key, z] : s.bristles) {
    key.body_a = r.Get<uint32_t>();
    key.body_b = r.Get<uint32_t>();
    key.feature = r.Get<uint64_t>();
    z = r.GetVec3();
  }
  const size_t actuators = r.GetCount(8 + sizeof(JointActuator));
  for (size_t i = 0; i < actuators; ++i) {
    const uint64_t joint = r.Get<uint64_t>();
    s.actuators[joint] = r.Get<JointActuator>();
  }
  s.pad_forces.resize(r.GetCount(8));
  for (auto& pad : s.pad_forces) {
    pad.resize(r.GetCount(24));
    for (Vec3& f : pad) f = r.GetVec3();
  }
  s.joint_wrenches.resize(r.GetCount(48));
  for (auto& wrench : s.joint_wrenches) {
    wrench[0] = r.GetVec3();
    wrench[1] = r.GetVec3();
  }
  s.contacts.resize(r.GetCount(56));
  for (auto& c : s.contacts) {
    c.body_a = r.Get<uint32_t>();
    c.body_b = r.Get<uint32_t>();
    c.point = r.GetVec3();
    c.force = r.GetVec3();
  }
  if (!r.done()) throw Error(ErrorCode::kInternal, what + ": trailing bytes after the state");
  return s;
}

}  // namespace graspsim::persistence
