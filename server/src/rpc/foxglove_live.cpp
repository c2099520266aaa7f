#include "rpc/foxglove_live.h"

#include "core/error.h"
#include "recording/frame_tap.h"
#include "rpc/recording_channels.h"

namespace graspsim::rpc {
namespace {

constexpr double kLiveInterval = 1.0 / 30;  // simulated s between frames: Foxglove's 3D panel needs no more

// Channels advertised on one connection as the encoder adds them.
class ConnectionWriter : public recording::ChannelWriter {
 public:
  explicit ConnectionWriter(std::shared_ptr<live::Connection> connection) : connection_(std::move(connection)) {}
  uint32_t AddChannel(const recording::ChannelSpec& spec) override {
    const uint32_t id = next_id_++;
    connection_->Advertise({{id, spec.topic, spec.message_encoding, spec.schema_name, spec.schema_encoding,
                             spec.schema_data}});
    return id;
  }
  bool Wanted(uint32_t channel) const override { return connection_->HasSubscribers(channel); }
  void Write(uint32_t channel, uint64_t time_ns, std::string_view payload) override {
    connection_->SendMessage(channel, time_ns, payload);
  }

 private:
  std::shared_ptr<live::Connection> connection_;
  uint32_t next_id_ = 1;
};

class LiveFeed : public recording::FrameConsumer {
 public:
  LiveFeed(std::shared_ptr<live::Connection> connection, std::string scene_id)
      : scene_id_(std::move(scene_id)), writer_(std::move(connection)), channels_(&writer_, {true, true, false}, {}) {}
  void Consume(const SceneSnapshot& frame) override {
    if (first_) {
      first_ = false;
      channels_.Log(frame.state->time, 2, "live feed of scene '" + scene_id_ + "'");
    }
    recording::FrameReadings readings(frame);
    channels_.Write(frame, readings);
  }
  std::chrono::milliseconds idle_interval() const override { return std::chrono::milliseconds(500); }

 private:
  const std::string scene_id_;
  bool first_ = true;
  ConnectionWriter writer_;
  ProtobufChannels channels_;
};

// Kept while the connection is open; stops the tap when it closes.
struct LiveSession {
  std::shared_ptr<recording::FrameTap> tap;
  ~LiveSession() { tap->Stop(); }
};

std::string SceneIdOf(const std::string& target) {
  std::string id = target.substr(0, target.find('?'));
  while (!id.empty() && id.front() == '/') id.erase(id.begin());
  while (!id.empty() && id.back() == '/') id.pop_back();
  return id;
}

}  // namespace

std::unique_ptr<live::FoxgloveServer> StartFoxgloveLive(const std::string& listen, SceneRegistry* registry) {
  live::FoxgloveServerOptions options;
  options.listen = listen;
  return std::make_unique<live::FoxgloveServer>(options, [registry](std::shared_ptr<live::Connection> connection)
                                                             -> std::shared_ptr<void> {
    const std::string id = SceneIdOf(connection->target());
    std::shared_ptr<Scene> scene;
    try {
      scene = registry->Get(id);
    } catch (const Error&) {
      std::string ids;
      for (const auto& s : registry->List()) ids += (ids.empty() ? "" : ", ") + s->id();
      connection->SendStatus(2, "no scene '" + id + "': connect to ws://<host>:<port>/<scene id>; scenes: " +
                                    (ids.empty() ? "none" : ids));
      return nullptr;
    }
    auto session = std::make_shared<LiveSession>();
    session->tap = std::make_shared<recording::FrameTap>(scene, std::make_unique<LiveFeed>(connection, id), kLiveInterval);
    session->tap->Start();
    return session;
  });
}

}  // namespace graspsim::rpc
