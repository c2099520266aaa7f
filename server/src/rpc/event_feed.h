// One upstream event stream, encoded once, for every viewer that asks for the same thing.
//
// Fifty browsers watching one scene used to cost fifty WatchScene streams: fifty snapshot messages built,
// serialised and parsed, and fifty JSON encodings of the same poses and contacts, per frame — the viewers'
// CPU competed with the simulation for the machine's cores (tests/bench/run viewers). A feed reads the
// upstream once on its own thread and keeps only the newest encoded event; each viewer's HTTP thread sends
// that text when it is ready for it, so a stalled browser skips events and never holds back the feed or the
// other viewers. Viewers share a feed only when everything that shapes the stream — scene, options and the
// credentials it was opened with — is the same (the caller's key), so nobody sees what their own request
// could not. The upstream is cancelled when its last viewer leaves.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

namespace graspsim::rpc {

// One Server-Sent Event ready to send. Some streams send a header (a snapshot's body id list) only when it
// changes: `with_header` is the event with it, for viewers that have not seen `header_epoch` yet.
// Streams that interleave several sources (one reading per tactile pad) name each event's `slot`: a viewer
// gets the newest event of every slot.
struct FeedEvent {
  std::string slot;
  std::string text;
  std::string with_header;  // empty: the stream has no header
  uint64_t header_epoch = 0;
};

// The upstream: blocking reads, the final status, and a cancel that may be called from any thread.
struct FeedSource {
  std::function<bool(FeedEvent*)> next;  // false at the end of the stream
  std::function<grpc::Status()> finish;
  std::function<void()> cancel;
};

class EventFeed : public std::enable_shared_from_this<EventFeed> {
 public:
  using Clock = std::chrono::steady_clock;
  using Write = std::function<bool(const std::string&)>;

  // Blocks until the first event or the end of the upstream. False with the upstream's status when it ended
  // before sending anything (an unknown scene, a refused request): the viewer answers that status instead.
  bool WaitFirst(grpc::Status* status);
  // Sends events to one viewer, the newest of each slot, until a write fails (the browser left), `until` passes (then
  // `*ended` is OK, "max_seconds reached") or the upstream ended (`*ended` is its status). False only when a
  // write failed.
  bool Serve(const Write& write, Clock::time_point until, grpc::Status* ended);

 private:
  friend class FeedRegistry;
  friend class FeedTicket;
  explicit EventFeed(FeedSource source) : source_(std::move(source)) {}
  void Start();
  void Pump();
  bool Join();   // false when the feed already ended or lost its last viewer
  void Leave();

  FeedSource source_;
  std::mutex mutex_;
  std::condition_variable changed_;
  struct Slot {
    std::shared_ptr<const FeedEvent> event;
    uint64_t sequence = 0;
  };
  std::vector<Slot> slots_;  // newest event per slot, a handful
  uint64_t sequence_ = 0;    // +1 per event
  bool ended_ = false;
  grpc::Status status_;
  int viewers_ = 0;
};

// A viewer's hold on a feed: leaves it when destroyed (also when the browser left before the first write).
class FeedTicket {
 public:
  explicit FeedTicket(std::shared_ptr<EventFeed> feed) : feed_(std::move(feed)) {}
  ~FeedTicket();
  FeedTicket(const FeedTicket&) = delete;
  FeedTicket& operator=(const FeedTicket&) = delete;
  EventFeed& feed() const { return *feed_; }

 private:
  std::shared_ptr<EventFeed> feed_;
};

class FeedRegistry {
 public:
  // Joins the running feed for `key`, or opens a new one with `open` (called under the registry's lock: it
  // must only start the call, not wait for it).
  std::unique_ptr<FeedTicket> Join(const std::string& key, const std::function<FeedSource()>& open);

 private:
  std::mutex mutex_;
  std::map<std::string, std::weak_ptr<EventFeed>> feeds_;
};

}  // namespace graspsim::rpc
