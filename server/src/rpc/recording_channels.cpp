#include "rpc/recording_channels.h"

#include <cmath>
#include <functional>
#include <set>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>

#include "core/error.h"
#include "foxglove/foxglove.pb.h"
#include "graspsim/v1/recording.pb.h"
#include "graspsim/v1/scene.pb.h"
#include "graspsim/v1/tactile.pb.h"
#include "persistence/state_codec.h"
#include "rpc/convert.h"
#include "rpc/packed_arrays.h"
#include "rpc/sensor_readings.h"
#include "rpc/watch_scene.h"
#include "sensors/readings.h"

namespace graspsim::rpc {
namespace {

namespace pb = google::protobuf;

// The schema of a protobuf channel: the message's file and every file it imports, dependencies first.
std::string DescriptorSetOf(const pb::Descriptor* descriptor) {
  pb::FileDescriptorSet set;
  std::set<std::string> seen;
  std::function<void(const pb::FileDescriptor*)> add = [&](const pb::FileDescriptor* file) {
    if (!seen.insert(file->name()).second) return;
    for (int i = 0; i < file->dependency_count(); ++i) add(file->dependency(i));
    file->CopyTo(set.add_file());
  };
  add(descriptor->file());
  return set.SerializeAsString();
}

recording::ChannelSpec ProtobufChannel(const std::string& topic, const pb::Descriptor* descriptor) {
  return {topic, "protobuf", descriptor->full_name(), "protobuf", DescriptorSetOf(descriptor)};
}

uint64_t Nanoseconds(double seconds) { return static_cast<uint64_t>(std::llround(std::max(0.0, seconds) * 1e9)); }

void SetTime(double seconds, pb::Timestamp* out) {
  const uint64_t ns = Nanoseconds(seconds);
  out->set_seconds(static_cast<int64_t>(ns / 1000000000u));
  out->set_nanos(static_cast<int32_t>(ns % 1000000000u));
}

void SetVector(const Vec3& v, foxglove::Vector3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}

void SetQuaternion(const Quat& q, foxglove::Quaternion* out) {
  out->set_x(q.x());
  out->set_y(q.y());
  out->set_z(q.z());
  out->set_w(q.w());
}

void SetPose(const Pose& pose, foxglove::Pose* out) {
  SetVector(pose.position, out->mutable_position());
  SetQuaternion(pose.orientation, out->mutable_orientation());
}

// One entity per body in its own frame (frame_locked: it moves with the body's transform on /tf).
void AddEntity(const BodySpec& body, double time, foxglove::SceneUpdate* update) {
  foxglove::SceneEntity* entity = update->add_entities();
  SetTime(time, entity->mutable_timestamp());
  entity->set_frame_id(body.id);
  entity->set_id(body.id);
  entity->set_frame_locked(true);
  const bool fixed = body.motion == BodyMotion::kStatic;
  auto color = [&](foxglove::Color* c) {
    c->set_r(fixed ? 0.55 : 0.3);
    c->set_g(fixed ? 0.55 : 0.6);
    c->set_b(fixed ? 0.55 : 0.9);
    c->set_a(1.0);
  };
  for (const Geometry& g : body.collision) {
    switch (g.kind) {
      case Geometry::Kind::kBox: {
        auto* cube = entity->add_cubes();
        SetPose(g.origin, cube->mutable_pose());
        SetVector(g.box_size, cube->mutable_size());
        color(cube->mutable_color());
        break;
      }
      case Geometry::Kind::kSphere: {
        auto* sphere = entity->add_spheres();
        SetPose(g.origin, sphere->mutable_pose());
        SetVector(Vec3::Constant(2 * g.radius), sphere->mutable_size());
        color(sphere->mutable_color());
        break;
      }
      case Geometry::Kind::kCylinder: {
        auto* cylinder = entity->add_cylinders();
        SetPose(g.origin, cylinder->mutable_pose());
        SetVector(Vec3(2 * g.radius, 2 * g.radius, g.length), cylinder->mutable_size());
        cylinder->set_bottom_scale(1);
        cylinder->set_top_scale(1);
        color(cylinder->mutable_color());
        break;
      }
      case Geometry::Kind::kMesh: {
        if (!g.mesh) break;
        auto* triangles = entity->add_triangles();
        SetPose(g.origin, triangles->mutable_pose());
        for (const auto& v : g.mesh->vertices) {
          auto* p = triangles->add_points();
          p->set_x(v.x());
          p->set_y(v.y());
          p->set_z(v.z());
        }
        for (const auto& t : g.mesh->triangles) {
          for (uint32_t i : t) triangles->add_indices(i);
        }
        color(triangles->mutable_color());
        break;
      }
    }
  }
}

}  // namespace

ChannelGroups ParseChannelGroups(const std::string& field, const std::vector<std::string>& names) {
  if (names.empty()) return {};
  ChannelGroups groups{false, false, false};
  for (const std::string& name : names) {
    if (name == "graspsim") {
      groups.graspsim = true;
    } else if (name == "foxglove") {
      groups.foxglove = true;
    } else if (name == "ros2") {
      groups.ros2 = true;
    } else {
      ThrowInvalidArgument(field + ": '" + name + "' is not a channel group; give graspsim, foxglove or ros2");
    }
  }
  return groups;
}

struct ProtobufChannels::Channels {
  recording::ChannelWriter* writer;
  ChannelGroups groups;
  std::vector<std::string> force_torque_joints;
  std::map<std::string, uint32_t> ids;  // by topic, added on first use
  std::shared_ptr<const std::vector<std::string>> last_body_ids;

  uint32_t Id(const std::string& topic, const pb::Descriptor* descriptor) {
    auto it = ids.find(topic);
    if (it == ids.end()) it = ids.emplace(topic, writer->AddChannel(ProtobufChannel(topic, descriptor))).first;
    return it->second;
  }
  // Returns whether the message was written (false: nobody reads the channel now).
  template <typename Message>
  bool Put(const std::string& topic, double time, const std::function<void(Message*)>& fill) {
    const uint32_t id = Id(topic, Message::descriptor());
    if (!writer->Wanted(id)) return false;
    Message message;
    fill(&message);
    writer->Write(id, Nanoseconds(time), message.SerializeAsString());
    return true;
  }
  // The scene descriptions go out when the body list changes, and until a reader took them (a live client that
  // subscribes after the first frame still gets them).
  bool scene_pending = true, foxglove_scene_pending = true;
  size_t edits_written = 0;
};

ProtobufChannels::ProtobufChannels(recording::ChannelWriter* writer, ChannelGroups groups,
                                   std::vector<std::string> force_torque_joints)
    : channels_(new Channels{writer, groups, std::move(force_torque_joints), {}, nullptr}) {}

ProtobufChannels::~ProtobufChannels() = default;

void ProtobufChannels::WriteMessage(const std::string& topic, double time, const pb::Message& message) {
  if (!channels_->groups.graspsim) return;
  const uint32_t id = channels_->Id(topic, message.GetDescriptor());
  if (channels_->writer->Wanted(id)) channels_->writer->Write(id, Nanoseconds(time), message.SerializeAsString());
}

void ProtobufChannels::WritePointCloud(const std::string& topic, double time, const std::vector<Vec3>& points) {
  if (!channels_->groups.foxglove) return;
  channels_->Put<foxglove::PointCloud>(topic, time, [&](foxglove::PointCloud* cloud) {
    SetTime(time, cloud->mutable_timestamp());
    cloud->set_frame_id("world");
    cloud->mutable_pose()->mutable_orientation()->set_w(1);
    cloud->set_point_stride(12);
    const char* names[] = {"x", "y", "z"};
    for (uint32_t i = 0; i < 3; ++i) {
      auto* field = cloud->add_fields();
      field->set_name(names[i]);
      field->set_offset(4 * i);
      field->set_type(foxglove::PackedElementField::FLOAT32);
    }
    cloud->set_data(PackFloat32Xyz(points));
  });
}

void ProtobufChannels::Log(double time, int level, const std::string& message) {
  if (!channels_->groups.foxglove) return;
  channels_->Put<foxglove::Log>("/log", time, [&](foxglove::Log* log) {
    SetTime(time, log->mutable_timestamp());
    log->set_level(static_cast<foxglove::Log::Level>(level));
    log->set_message(message);
    log->set_name("graspsim-server");
  });
}

void ProtobufChannels::Write(const SceneSnapshot& frame, recording::FrameReadings& readings) {
  Channels& c = *channels_;
  const SceneModel& model = *frame.model;
  const SceneState& state = *frame.state;
  const double time = state.time;
  if (c.last_body_ids != frame.body_ids) c.scene_pending = c.foxglove_scene_pending = true;
  c.last_body_ids = frame.body_ids;

  if (c.groups.graspsim) {
    for (; c.edits_written < frame.edits->size(); ++c.edits_written) {
      const SceneOp& op = *(*frame.edits)[c.edits_written];
      c.Put<v1::RecordedEdit>("/graspsim/edit", time, [&](v1::RecordedEdit* edit) {
        edit->set_kind(op.kind);
        edit->set_request(op.payload);
        edit->set_path(op.path);
        edit->set_sha256(op.sha256);
        if (op.file) edit->set_file(*op.file);
      });
    }
    if (c.scene_pending) {
      c.scene_pending = !c.Put<v1::Scene>("/graspsim/scene", time, [&](v1::Scene* scene) {
        SceneView view;
        view.model = frame.model;
        view.state = state;
        view.revision = frame.revision;
        ToProto(view, /*include_geometry=*/true, scene);
      });
    }
    c.Put<v1::SceneSnapshot>("/graspsim/snapshot", time, [&](v1::SceneSnapshot* out) { ToProto(frame, out); });
    c.Put<v1::RecordedState>("/graspsim/state", time, [&](v1::RecordedState* out) {
      out->set_time(time);
      out->set_revision(frame.revision);
      out->set_state(persistence::EncodeState(state));
      out->set_edits(frame.edits->size());
    });
    for (size_t pad = 0; pad < model.tactile_arrays.size(); ++pad) {
      c.Put<v1::SensorReading>("/graspsim/sensor", time, [&](v1::SensorReading* out) {
        out->set_sensor_id(model.tactile_arrays[pad].id);
        out->set_time(time);
        ToProto(readings.Pad(pad), out->mutable_tactile());
      });
    }
    for (const std::string& joint_id : c.force_torque_joints) {
      const auto found = model.joint_index.find(joint_id);
      if (found == model.joint_index.end()) continue;
      c.Put<v1::SensorReading>("/graspsim/sensor", time, [&](v1::SensorReading* out) {
        out->set_sensor_id(joint_id);
        out->set_time(time);
        ToProto(ReadForceTorque(model, state, found->second), out->mutable_force_torque());
      });
    }
  }

  if (c.groups.foxglove) {
    if (c.foxglove_scene_pending) {
      c.foxglove_scene_pending = !c.Put<foxglove::SceneUpdate>("/scene", time, [&](foxglove::SceneUpdate* update) {
        auto* deletion = update->add_deletions();  // the body list changed: start the 3D scene afresh
        SetTime(time, deletion->mutable_timestamp());
        deletion->set_type(foxglove::SceneEntityDeletion::ALL);
        for (const BodySpec& body : model.bodies) AddEntity(body, time, update);
      });
    }
    c.Put<foxglove::FrameTransforms>("/tf", time, [&](foxglove::FrameTransforms* transforms) {
      for (size_t i = 0; i < model.bodies.size(); ++i) {
        foxglove::FrameTransform* t = transforms->add_transforms();
        SetTime(time, t->mutable_timestamp());
        t->set_parent_frame_id("world");
        t->set_child_frame_id(model.bodies[i].id);
        SetVector(state.body_poses[i].position, t->mutable_translation());
        SetQuaternion(state.body_poses[i].orientation, t->mutable_rotation());
      }
    });
    for (size_t pad = 0; pad < model.tactile_arrays.size(); ++pad) {
      const std::string& id = model.tactile_arrays[pad].id;
      c.Put<foxglove::RawImage>("/tactile/" + id, time, [&](foxglove::RawImage* image) {
        const TactileFrame& reading = readings.Pad(pad);
        SetTime(time, image->mutable_timestamp());
        image->set_frame_id(id);
        image->set_width(reading.cols);
        image->set_height(reading.rows);
        image->set_encoding("mono16");  // little-endian 16-bit, the DSACON32's 12-bit intensities
        image->set_step(2 * reading.cols);
        image->set_data(Pack(reading.intensities));
      });
    }
  }
}

}  // namespace graspsim::rpc
