#include "rpc/gateway_stream.h"

#include <deque>
#include <mutex>

#include "core/log.h"
#include "rpc/call.h"
#include "rpc/convert_gateway.h"

namespace graspsim::rpc {
namespace {

class GatewayStream final : public grpc::ServerBidiReactor<v1::GatewayMessage, v1::GatewayCommand>,
                            public gateway::SessionSink {
 public:
  GatewayStream(grpc::CallbackServerContext* context, gateway::GatewayHub* hub) : context_(context), hub_(hub) {
    session_ = hub_->Open(this);
    Log(LogLevel::kInfo, "gateway connected", {{"peer", context_->peer()}});
    StartRead(&in_);
  }

  // SessionSink: called with the hub's lock held; only queue.
  void SendCommand(const gateway::Command& command) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    ToProto(command, queue_.emplace_back().mutable_command());
    WriteNextLocked();
  }
  void SendHeartbeat(double time) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_ || heartbeat_queued_) return;
    queue_.emplace_back().mutable_heartbeat()->set_time(time);
    heartbeat_queued_ = true;
    WriteNextLocked();
  }

  void End(const std::string& reason) override {
    std::lock_guard<std::mutex> lock(mutex_);
    FinishLocked(grpc::Status(grpc::StatusCode::UNAVAILABLE, reason));
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the gateway half-closed or went away
      hub_->Close(session_, "the gateway closed its stream");
      std::lock_guard<std::mutex> lock(mutex_);
      FinishLocked(grpc::Status::OK);
      return;
    }
    const grpc::Status status = Handle("GatewayService/Connect", *context_, [&] { Dispatch(); });
    if (!status.ok()) {
      hub_->Close(session_, status.error_message());
      std::lock_guard<std::mutex> lock(mutex_);
      FinishLocked(status);
      return;
    }
    StartRead(&in_);
  }
  void OnWriteDone(bool ok) override {
    std::lock_guard<std::mutex> lock(mutex_);
    writing_ = false;
    if (queue_.front().has_heartbeat()) heartbeat_queued_ = false;
    queue_.pop_front();
    if (!ok) {
      FinishLocked(grpc::Status(grpc::StatusCode::UNAVAILABLE, "the gateway's stream broke"));
      return;
    }
    if (finish_pending_) {
      FinishLocked(*finish_pending_);
      return;
    }
    WriteNextLocked();
  }
  void OnCancel() override {
    hub_->Close(session_, "the gateway's stream was cancelled");
    std::lock_guard<std::mutex> lock(mutex_);
    FinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "the gateway's stream was cancelled"));  // OnDone needs it
  }
  void OnDone() override {
    hub_->Close(session_, "the gateway's stream ended");  // after this the hub never calls the sink again
    Log(LogLevel::kInfo, "gateway disconnected", {{"peer", context_->peer()}});
    delete this;
  }

 private:
  void Dispatch() {
    switch (in_.message_case()) {
      case v1::GatewayMessage::kRegisterDevice:
        hub_->Register(session_, DeviceFromProto(in_.register_device()));
        break;
      case v1::GatewayMessage::kDeviceReading:
        hub_->OnReading(session_, ReadingFromProto(in_.device_reading()));
        break;
      case v1::GatewayMessage::kResult:
        hub_->OnResult(session_, ResultFromProto(in_.result()));
        break;
      case v1::GatewayMessage::kHeartbeat:
      case v1::GatewayMessage::kReading:  // no server-side consumer for other sensors yet
      case v1::GatewayMessage::MESSAGE_NOT_SET:
        break;
    }
  }
  void WriteNextLocked() {
    if (writing_ || finished_ || queue_.empty()) return;
    writing_ = true;
    StartWrite(&queue_.front());  // deque: the element stays put while others are appended
  }
  // A finish waits for the write in flight: the reactor never has both outstanding.
  void FinishLocked(const grpc::Status& status) {
    if (finished_) return;
    if (writing_) {
      if (!finish_pending_) finish_pending_ = std::make_unique<grpc::Status>(status);
      return;
    }
    finished_ = true;
    Finish(status);
  }

  grpc::CallbackServerContext* context_;
  gateway::GatewayHub* hub_;
  uint64_t session_ = 0;
  v1::GatewayMessage in_;
  std::mutex mutex_;
  std::deque<v1::GatewayCommand> queue_;
  bool writing_ = false, heartbeat_queued_ = false, finished_ = false;
  std::unique_ptr<grpc::Status> finish_pending_;
};

}  // namespace

grpc::ServerBidiReactor<v1::GatewayMessage, v1::GatewayCommand>* StartGatewayStream(
    grpc::CallbackServerContext* context, gateway::GatewayHub* hub) {
  return new GatewayStream(context, hub);
}

}  // namespace graspsim::rpc
