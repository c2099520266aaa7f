#include "world/scene.h"

#include <algorithm>
#include <set>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"

namespace graspsim {
namespace {

// Sizes the per-body and per-joint dynamic state (velocities, sleep) to the model; new entries are at rest.
void SizeDynamicState(const SceneModel& model, SceneState* state) {
  state->body_velocities.resize(model.bodies.size());
  state->sleeping.resize(model.bodies.size(), false);
  state->rest_time.resize(model.bodies.size(), 0);
  state->joint_velocities.resize(model.joints.size(), 0);
}

std::string Quoted(const std::string& s) { return "'" + s + "'"; }

bool IsFollower(const JointSpec& joint) { return joint.mimic.has_value(); }

}  // namespace

Scene::Scene(std::string id, std::string name, const Limits& limits)
    : id_(std::move(id)), name_(std::move(name)), limits_(limits), model_(std::make_shared<SceneModel>()) {
  std::lock_guard<std::mutex> lock(mutex_);
  PublishLocked();
}

SceneView Scene::View() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {id_, name_, revision_, model_, state_, files_};
}

void Scene::Read(const ReadFn& read) const {
  std::lock_guard<std::mutex> lock(mutex_);
  read(*model_, state_, revision_);
}

bool Scene::TryRead(const ReadFn& read) const {
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return false;
  read(*model_, state_, revision_);
  return true;
}

void Scene::AttachJournal(SceneJournal* journal) {
  std::lock_guard<std::mutex> writing(write_mutex_);
  journal_ = journal;
  journaled_revision_ = revision_;
}

void Scene::RestoreState(SceneState state, uint64_t revision) {
  std::lock_guard<std::mutex> writing(write_mutex_);
  const SceneModel& model = *model_;
  const size_t bodies = model.bodies.size(), joints = model.joints.size();
  if (state.body_poses.size() != bodies || state.body_velocities.size() != bodies ||
      state.sleeping.size() != bodies || state.rest_time.size() != bodies ||
      state.joint_positions.size() != joints || state.joint_velocities.size() != joints ||
      (!state.actuators.empty() && state.actuators.rbegin()->first >= joints)) {
    throw Error(ErrorCode::kInternal, "scene " + Quoted(id_) + ": the stored state has " +
                                          std::to_string(state.body_poses.size()) + " bodies and " +
                                          std::to_string(state.joint_positions.size()) + " joints, the model " +
                                          std::to_string(bodies) + " and " + std::to_string(joints));
  }
  std::lock_guard<std::mutex> visible(mutex_);
  state_ = std::move(state);
  revision_ = revision;
  PublishLocked();
}

void Scene::Checkpoint() {
  std::lock_guard<std::mutex> writing(write_mutex_);
  if (!journal_ || journaled_revision_ == revision_) return;
  journal_->SceneChanged(id_, nullptr, state_, revision_);
  journaled_revision_ = revision_;
}

void Scene::Journal(const SceneOp* op, const SceneState& state, bool changes_model) {
  if (!journal_) return;
  // A model edit the journal cannot replay would leave a log and a state that disagree on the next start.
  if (changes_model && !op) throw Error(ErrorCode::kInternal, "scene " + Quoted(id_) + ": a model edit without its op");
  journal_->SceneChanged(id_, op, state, revision_ + 1);
  journaled_revision_ = revision_ + 1;
}

void Scene::AppendEditLocked(const SceneOp* op) {
  if (!op) return;
  auto edits = std::make_shared<SceneEdits>(*edits_);  // copies pointers, not requests
  edits->push_back(std::make_shared<const SceneOp>(*op));
  edits_ = std::move(edits);
}

std::shared_ptr<const SceneSnapshot> Scene::DetailedSnapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return SnapshotLocked(state_, revision_, true, false);
}

uint64_t Scene::revision() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return revision_;
}

std::map<std::string, StoredFile> Scene::Files() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return files_;
}

void Scene::PutFile(const std::string& path, std::shared_ptr<const std::string> bytes, const std::string& sha256,
                    const SceneOp* op) {
  std::lock_guard<std::mutex> writing(write_mutex_);
  const auto existing = files_.find(path);
  const uint64_t replaced = existing == files_.end() ? 0 : existing->second.bytes->size();
  const uint64_t total = file_bytes_ - replaced + bytes->size();
  if (total > limits_.max_scene_file_bytes) {
    ThrowResourceExhausted("upload " + Quoted(path) + ": the scene's files would take " + std::to_string(total) +
                           " bytes, above the limit of " + std::to_string(limits_.max_scene_file_bytes));
  }
  Journal(op, state_, true);
  std::lock_guard<std::mutex> visible(mutex_);
  AppendEditLocked(op);
  file_bytes_ = total;
  files_[path] = {std::move(bytes), sha256};
  ++revision_;  // files are part of the scene (GetScene lists them), but move nothing: no snapshot
}

void Scene::CheckIdFree(const std::string& field, const std::string& id) const {
  if (model_->body_index.count(id) || model_->robot_index.count(id) || model_->joint_index.count(id) ||
      model_->tactile_index.count(id)) {
    throw Error(ErrorCode::kAlreadyExists, field + ": " + Quoted(id) + " already exists in scene " + Quoted(id_));
  }
}

BodySpec Scene::AddObject(BodySpec body, const Pose& pose, const SceneOp* op) {
  std::lock_guard<std::mutex> writing(write_mutex_);
  CheckIdFree("name", body.id);
  if (model_->bodies.size() + 1 > limits_.max_bodies_per_scene) {
    ThrowResourceExhausted("name " + Quoted(body.id) + ": scene " + Quoted(id_) + " already has " +
                           std::to_string(model_->bodies.size()) + " bodies, the limit is " +
                           std::to_string(limits_.max_bodies_per_scene));
  }
  auto model = std::make_shared<SceneModel>(*model_);
  model->bodies.push_back(body);
  model->Reindex();
  SceneState state = state_;
  state.body_poses.push_back(pose);
  SizeDynamicState(*model, &state);
  Journal(op, state, true);
  std::lock_guard<std::mutex> visible(mutex_);
  model_ = std::move(model);
  state_ = std::move(state);
  CommitLocked(op);
  return body;
}

AddedRobot Scene::AddRobot(const std::string& name, const std::string& source, const RobotDescription& description,
                           const Pose& base_pose, const SceneOp* op) {
  std::lock_guard<std::mutex> writing(write_mutex_);
  const std::string prefix = name + "/";
  CheckIdFree("name", name);
  if (model_->bodies.size() + description.links.size() > limits_.max_bodies_per_scene) {
    ThrowResourceExhausted("name " + Quoted(name) + ": adding " + std::to_string(description.links.size()) +
                           " links to scene " + Quoted(id_) + " with " + std::to_string(model_->bodies.size()) +
                           " bodies exceeds the limit of " + std::to_string(limits_.max_bodies_per_scene));
  }
  AddedRobot added;
  added.robot.id = name;
  added.robot.source = source;
  added.robot.base_body = prefix + description.root_link;
  for (BodySpec link : description.links) {
    link.id = prefix + link.id;
    link.robot_id = name;
    link.motion = BodyMotion::kArticulated;
    CheckIdFree("name", link.id);
    added.robot.body_ids.push_back(link.id);
    added.bodies.push_back(std::move(link));
  }
  for (JointSpec joint : description.joints) {
    joint.id = prefix + joint.id;
    joint.robot_id = name;
    joint.parent_body = prefix + joint.parent_body;
    joint.child_body = prefix + joint.child_body;
    if (joint.mimic) joint.mimic->joint_id = prefix + joint.mimic->joint_id;
    CheckIdFree("name", joint.id);
    added.robot.joint_ids.push_back(joint.id);
    added.joints.push_back(std::move(joint));
  }
  for (TactileArraySpec pad : description.tactile_arrays) {
    pad.id = prefix + pad.id;
    pad.body_id = prefix + pad.body_id;
    CheckIdFree("name", pad.id);
    added.robot.tactile_array_ids.push_back(pad.id);
    added.tactile_arrays.push_back(std::move(pad));
  }

  auto model = std::make_shared<SceneModel>(*model_);
  model->bodies.insert(model->bodies.end(), added.bodies.begin(), added.bodies.end());
  model->joints.insert(model->joints.end(), added.joints.begin(), added.joints.end());
  model->tactile_arrays.insert(model->tactile_arrays.end(), added.tactile_arrays.begin(), added.tactile_arrays.end());
  model->robots.push_back(added.robot);
  model->Reindex();

  SceneState state = state_;
  state.body_poses.resize(model->bodies.size(), base_pose);
  // Joints start at zero clamped into their limits, so a gripper whose range excludes 0 starts valid.
  for (const JointSpec& joint : added.joints) {
    const bool limited = joint.type == JointType::kRevolute || joint.type == JointType::kPrismatic;
    state.joint_positions.push_back(limited ? std::clamp(0.0, joint.lower, joint.upper) : 0.0);
  }
  UpdateRobotLinkPoses(*model, model->robots.size() - 1, &state);
  SizeDynamicState(*model, &state);
  Journal(op, state, true);
  std::lock_guard<std::mutex> visible(mutex_);
  model_ = std::move(model);
  state_ = std::move(state);
  CommitLocked(op);
  return added;
}

std::vector<std::string> Scene::Remove(const std::string& id, const SceneOp* op) {
  std::lock_guard<std::mutex> writing(write_mutex_);
  std::set<std::string> bodies, joints, pads;
  if (auto robot = model_->robot_index.find(id); robot != model_->robot_index.end()) {
    const RobotSpec& spec = model_->robots[robot->second];
    bodies.insert(spec.body_ids.begin(), spec.body_ids.end());
    joints.insert(spec.joint_ids.begin(), spec.joint_ids.end());
    pads.insert(spec.tactile_array_ids.begin(), spec.tactile_array_ids.end());
  } else if (auto body = model_->body_index.find(id); body != model_->body_index.end()) {
    const BodySpec& spec = model_->bodies[body->second];
    if (!spec.robot_id.empty()) {
      throw Error(ErrorCode::kFailedPrecondition, "id: " + Quoted(id) + " is a link of robot " +
                                                      Quoted(spec.robot_id) + "; remove the whole robot instead");
    }
    bodies.insert(id);
  } else {
    ThrowNotFound("id: no object or robot " + Quoted(id) + " in scene " + Quoted(id_));
  }

  auto model = std::make_shared<SceneModel>();
  model->simulation = model_->simulation;
  SceneState state;
  state.time = state_.time;
  state.step = state_.step;
  // Every body wakes up: one resting on what was removed must fall.
  std::map<uint32_t, uint32_t> new_body_index;
  for (size_t i = 0; i < model_->bodies.size(); ++i) {
    if (bodies.count(model_->bodies[i].id)) continue;
    new_body_index[static_cast<uint32_t>(i)] = static_cast<uint32_t>(model->bodies.size());
    model->bodies.push_back(model_->bodies[i]);
    state.body_poses.push_back(state_.body_poses[i]);
    state.body_velocities.push_back(state_.body_velocities[i]);
    state.sleeping.push_back(false);
    state.rest_time.push_back(0);
  }
  // The contacts between the bodies that stay keep their bristles (a held object keeps its grip), re-indexed;
  // the renumbering keeps the keys' order.
  for (const auto& [key, z] : state_.bristles) {
    const auto a = new_body_index.find(key.body_a), b = new_body_index.find(key.body_b);
    if (a != new_body_index.end() && b != new_body_index.end()) {
      state.bristles.emplace_back(ContactKey{a->second, b->second, key.feature}, z);
    }
  }
  std::map<size_t, size_t> new_joint_index;
  for (size_t i = 0; i < model_->joints.size(); ++i) {
    if (joints.count(model_->joints[i].id)) continue;
    new_joint_index[i] = model->joints.size();
    model->joints.push_back(model_->joints[i]);
    state.joint_positions.push_back(state_.joint_positions[i]);
    state.joint_velocities.push_back(state_.joint_velocities[i]);
  }
  for (const auto& [joint, actuator] : state_.actuators) {
    if (new_joint_index.count(joint)) state.actuators[new_joint_index[joint]] = actuator;
  }
  for (const auto& pad : model_->tactile_arrays) {
    if (!pads.count(pad.id)) model->tactile_arrays.push_back(pad);
  }
  for (const auto& robot : model_->robots) {
    if (robot.id != id) model->robots.push_back(robot);
  }
  model->Reindex();
  Journal(op, state, true);
  std::lock_guard<std::mutex> visible(mutex_);
  model_ = std::move(model);
  state_ = std::move(state);
  CommitLocked(op);
  return {bodies.begin(), bodies.end()};
}

size_t Scene::BodyIndex(const std::string& id) const {
  if (auto robot = model_->robot_index.find(id); robot != model_->robot_index.end()) {
    return model_->body_index.at(model_->robots[robot->second].base_body);
  }
  auto body = model_->body_index.find(id);
  if (body == model_->body_index.end()) ThrowNotFound("body_id: no body " + Quoted(id) + " in scene " + Quoted(id_));
  return body->second;
}

size_t Scene::JointIndex(const std::string& id) const {
  auto joint = model_->joint_index.find(id);
  if (joint == model_->joint_index.end()) {
    ThrowNotFound("joint_id: no joint " + Quoted(id) + " in scene " + Quoted(id_));
  }
  return joint->second;
}

uint64_t Scene::SetBodyPoses(const std::vector<std::pair<std::string, Pose>>& poses,
                             const std::vector<std::pair<std::string, BodyVelocity>>& velocities) {
  std::lock_guard<std::mutex> writing(write_mutex_);
  SceneState state = state_;
  state.body_velocities.resize(model_->bodies.size());
  for (const auto& [id, velocity] : velocities) {
    const size_t index = BodyIndex(id);
    const BodySpec& body = model_->bodies[index];
    if (body.motion != BodyMotion::kFree) {
      throw Error(ErrorCode::kFailedPrecondition,
                  "velocity: body " + Quoted(id) + (body.robot_id.empty() ? " is static" : " is part of a robot") +
                      "; only free objects have a velocity of their own (robots move by their joints)");
    }
    CheckFinite("velocity[" + id + "].linear", velocity.linear);
    CheckFinite("velocity[" + id + "].angular", velocity.angular);
    state.body_velocities[index] = velocity;
    if (index < state.sleeping.size()) {
      state.sleeping[index] = false;
      state.rest_time[index] = 0;
    }
  }
  std::set<std::string> moved_robots;
  for (const auto& [id, pose] : poses) {
    const size_t index = BodyIndex(id);
    const BodySpec& body = model_->bodies[index];
    if (!body.robot_id.empty()) {
      const RobotSpec& robot = model_->robots[model_->robot_index.at(body.robot_id)];
      if (robot.base_body != body.id) {
        throw Error(ErrorCode::kFailedPrecondition,
                    "body_id: " + Quoted(id) + " is a link of robot " + Quoted(robot.id) +
                        " placed by its joints; set the robot's base pose (id " + Quoted(robot.id) +
                        ") or its joint positions");
      }
      moved_robots.insert(robot.id);
    }
    state.body_poses[index] = pose;
    if (index < state.sleeping.size()) {  // a moved body is no longer at rest
      state.sleeping[index] = false;
      state.rest_time[index] = 0;
    }
  }
  for (const std::string& robot : moved_robots) {
    UpdateRobotLinkPoses(*model_, model_->robot_index.at(robot), &state);
  }
  state.contacts.clear();  // they were where the bodies no longer are; the next step finds the new ones
  Journal(nullptr, state);
  std::lock_guard<std::mutex> visible(mutex_);
  state_ = std::move(state);
  CommitLocked(nullptr);
  return revision_;
}

uint64_t Scene::SetJointPositions(const std::vector<std::pair<std::string, double>>& positions,
                                  const std::vector<std::pair<std::string, double>>& velocities) {
  std::lock_guard<std::mutex> writing(write_mutex_);
  SceneState state = state_;
  state.joint_velocities.resize(model_->joints.size());
  std::set<std::string> moved_robots;
  for (const auto& [id, velocity] : velocities) {
    const JointSpec& joint = model_->joints[JointIndex(id)];
    CheckFinite("velocities[" + id + "].velocity", velocity);
    if (joint.type == JointType::kFixed || IsFollower(joint)) {
      ThrowInvalidArgument("joint_id: " + Quoted(id) + (IsFollower(joint) ? " mimics another joint; set the leader"
                                                                           : " is a fixed joint and has no velocity"));
    }
    state.joint_velocities[model_->joint_index.at(id)] = velocity;
    moved_robots.insert(joint.robot_id);
  }
  for (const auto& [id, position] : positions) {
    const JointSpec& joint = model_->joints[JointIndex(id)];
    CheckFinite("positions[" + id + "].position", position);
    if (joint.type == JointType::kFixed) {
      ThrowInvalidArgument("joint_id: " + Quoted(id) + " is a fixed joint and has no position");
    }
    if (IsFollower(joint)) {
      ThrowInvalidArgument("joint_id: " + Quoted(id) + " mimics " + Quoted(joint.mimic->joint_id) +
                           "; set the leader instead");
    }
    state.joint_positions[model_->joint_index.at(id)] = position;
    moved_robots.insert(joint.robot_id);
  }
  // Followers take their leader's value, then every limit is checked, followers included.
  for (size_t j = 0; j < model_->joints.size(); ++j) {
    const JointSpec& joint = model_->joints[j];
    if (!moved_robots.count(joint.robot_id)) continue;
    if (IsFollower(joint)) {
      const size_t leader = model_->joint_index.at(joint.mimic->joint_id);
      state.joint_positions[j] = joint.mimic->multiplier * state.joint_positions[leader] + joint.mimic->offset;
      state.joint_velocities[j] = joint.mimic->multiplier * state.joint_velocities[leader];
    }
    const bool limited = joint.type == JointType::kRevolute || joint.type == JointType::kPrismatic;
    const double q = state.joint_positions[j];
    if (limited && (q < joint.lower - 1e-12 || q > joint.upper + 1e-12)) {
      ThrowInvalidArgument("positions[" + joint.id + "].position: " + FormatNumber(q) + " is outside the limits [" +
                           FormatNumber(joint.lower) + ", " + FormatNumber(joint.upper) + "] of joint " +
                           Quoted(joint.id));
    }
  }
  for (const std::string& robot : moved_robots) {
    UpdateRobotLinkPoses(*model_, model_->robot_index.at(robot), &state);
  }
  state.contacts.clear();  // they were where the bodies no longer are; the next step finds the new ones
  Journal(nullptr, state);
  std::lock_guard<std::mutex> visible(mutex_);
  state_ = std::move(state);
  CommitLocked(nullptr);
  return revision_;
}

uint64_t Scene::Update(const StateChange& change, bool journal) {
  std::lock_guard<std::mutex> writing(write_mutex_);
  SceneState state = state_;
  change(model_, &state);
  if (journal) Journal(nullptr, state);
  std::lock_guard<std::mutex> visible(mutex_);
  state_ = std::move(state);
  CommitLocked(nullptr);
  return revision_;
}

uint64_t Scene::SetSimulationParams(const SimulationParams& params, const SceneOp* op) {
  std::lock_guard<std::mutex> writing(write_mutex_);
  auto model = std::make_shared<SceneModel>(*model_);
  model->simulation = params;
  Journal(op, state_, true);
  std::lock_guard<std::mutex> visible(mutex_);
  model_ = std::move(model);
  CommitLocked(op);
  return revision_;
}

void Scene::CommitLocked(const SceneOp* op) {
  AppendEditLocked(op);
  ++revision_;
  PublishLocked();
}

void Scene::PublishLocked() {
  const bool detail = hub_.detail_wanted();
  if (detail) last_detail_time_ = state_.time;
  hub_.Publish(SnapshotLocked(state_, revision_, detail, true));
}

void Scene::PublishDuringUpdate(const SceneState& state) {
  if (!hub_.detail_wanted()) return;
  // Spaced as the watchers asked (recordings default to 30 frames per simulated second); time may also go back
  // (a replay seeks), which always publishes.
  const double since = state.time - last_detail_time_;
  if (since >= 0 && since < hub_.detail_interval() - 1e-9) return;
  last_detail_time_ = state.time;
  std::lock_guard<std::mutex> lock(mutex_);  // the snapshot caches are shared with the readers
  hub_.Publish(SnapshotLocked(state, revision_ + 1, true, true));
}

std::shared_ptr<SceneSnapshot> Scene::SnapshotLocked(const SceneState& state, uint64_t revision, bool detail,
                                                     bool publish) const {
  auto snapshot = std::make_shared<SceneSnapshot>();
  // A detailed snapshot taken outside a publication shows the last published sequence: watchers count gaps.
  snapshot->sequence = publish ? ++snapshot_sequence_ : snapshot_sequence_;
  snapshot->revision = revision;
  snapshot->time = state.time;
  // Id lists change only with the model; reuse them between snapshots while they are the same (a new model with
  // the same ids, e.g. new simulation parameters, keeps them too: watchers compare the pointers).
  if (snapshot_ids_model_ != model_) {
    std::vector<std::string> body_ids, joint_ids;
    for (const auto& body : model_->bodies) body_ids.push_back(body.id);
    for (const auto& joint : model_->joints) joint_ids.push_back(joint.id);
    if (!snapshot_body_ids_ || *snapshot_body_ids_ != body_ids) {
      snapshot_body_ids_ = std::make_shared<const std::vector<std::string>>(std::move(body_ids));
    }
    if (!snapshot_joint_ids_ || *snapshot_joint_ids_ != joint_ids) {
      snapshot_joint_ids_ = std::make_shared<const std::vector<std::string>>(std::move(joint_ids));
    }
    snapshot_ids_model_ = model_;
  }
  snapshot->body_ids = snapshot_body_ids_;
  snapshot->joint_ids = snapshot_joint_ids_;
  snapshot->body_poses.reserve(7 * state.body_poses.size());
  for (const Pose& pose : state.body_poses) {
    const Quat& q = pose.orientation;
    for (double v : {pose.position.x(), pose.position.y(), pose.position.z(), q.w(), q.x(), q.y(), q.z()}) {
      snapshot->body_poses.push_back(v);
    }
  }
  snapshot->joint_positions = state.joint_positions;
  snapshot->contacts.reserve(6 * state.contacts.size());
  snapshot->contact_bodies.reserve(2 * state.contacts.size());
  for (const auto& contact : state.contacts) {
    for (double v : {contact.point.x(), contact.point.y(), contact.point.z(), contact.force.x(), contact.force.y(),
                     contact.force.z()}) {
      snapshot->contacts.push_back(v);
    }
    snapshot->contact_bodies.insert(snapshot->contact_bodies.end(), {contact.body_a, contact.body_b});
  }
  if (detail) {
    snapshot->model = model_;
    snapshot->state = std::make_shared<const SceneState>(state);
    snapshot->edits = edits_;
  }
  return snapshot;
}

}  // namespace graspsim
