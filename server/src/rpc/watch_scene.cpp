#include "rpc/watch_scene.h"

#include "rpc/failed_call.h"
#include "rpc/packed_arrays.h"
#include "rpc/run_reactor.h"
#include "rpc/snapshot_stream.h"

namespace graspsim::rpc {
namespace {

// Writes each snapshot as it is: the message is built under the stream's mutex and must stay untouched while
// its write is in flight (the base starts no send before the write completes).
class WatchStream : public SnapshotStream<v1::SceneSnapshot> {
 public:
  using SnapshotStream::SnapshotStream;

 private:
  void SendLocked(const SceneSnapshot& snapshot) override {
    ToProto(snapshot, &message_);
    WriteLocked(&message_);
  }

  v1::SceneSnapshot message_;
};

}  // namespace

void ToProto(const SceneSnapshot& snapshot, v1::SceneSnapshot* out) {
  out->Clear();
  out->set_sequence(snapshot.sequence);
  out->set_revision(snapshot.revision);
  out->set_time(snapshot.time);
  for (const auto& id : *snapshot.body_ids) out->add_body_ids(id);
  out->set_body_poses(Pack(snapshot.body_poses));
  for (const auto& id : *snapshot.joint_ids) out->add_joint_ids(id);
  out->set_joint_positions(Pack(snapshot.joint_positions));
  out->set_contacts(Pack(snapshot.contacts));
  out->set_contact_bodies(Pack(snapshot.contact_bodies));
}

grpc::ServerWriteReactor<v1::SceneSnapshot>* StartWatch(std::shared_ptr<Scene> scene,
                                                        std::chrono::nanoseconds min_interval) {
  auto* reactor = new RunReactor<v1::SceneSnapshot, WatchStream>(std::move(scene), min_interval, "watch");
  reactor->run()->Start();
  return reactor;
}

}  // namespace graspsim::rpc
