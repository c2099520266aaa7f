#include "rpc/event_feed.h"

#include <algorithm>
#include <limits>
#include <thread>

namespace graspsim::rpc {

void EventFeed::Start() {
  // The thread holds the feed until the upstream ends: after the last viewer left, Leave cancels it.
  std::thread([self = shared_from_this()] { self->Pump(); }).detach();
}

void EventFeed::Pump() {
  for (;;) {
    auto event = std::make_shared<FeedEvent>();
    if (!source_.next(event.get())) break;
    std::lock_guard lock(mutex_);
    auto slot = std::find_if(slots_.begin(), slots_.end(), [&](const Slot& s) { return s.event->slot == event->slot; });
    if (slot == slots_.end()) slot = slots_.insert(slots_.end(), Slot{});
    slot->event = std::move(event);
    slot->sequence = ++sequence_;
    changed_.notify_all();
  }
  grpc::Status status = source_.finish();
  std::lock_guard lock(mutex_);
  status_ = std::move(status);
  ended_ = true;
  changed_.notify_all();
}

bool EventFeed::Join() {
  std::lock_guard lock(mutex_);
  if (ended_ || viewers_ < 0) return false;
  ++viewers_;
  return true;
}

void EventFeed::Leave() {
  std::lock_guard lock(mutex_);
  if (--viewers_ > 0) return;
  viewers_ = -1;  // closed for joining: a new viewer opens a new feed rather than join one being cancelled
  if (!ended_) source_.cancel();
}

bool EventFeed::WaitFirst(grpc::Status* status) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return sequence_ > 0 || ended_; });
  if (sequence_ > 0) return true;
  *status = status_;
  return false;
}

bool EventFeed::Serve(const Write& write, Clock::time_point until, grpc::Status* ended) {
  uint64_t sent = 0;
  uint64_t header_epoch = std::numeric_limits<uint64_t>::max();  // nothing seen yet
  std::vector<std::pair<uint64_t, std::shared_ptr<const FeedEvent>>> events;
  for (;;) {
    events.clear();
    {
      std::unique_lock lock(mutex_);
      if (!changed_.wait_until(lock, until, [&] { return sequence_ > sent || ended_; })) {
        *ended = grpc::Status(grpc::StatusCode::OK, "max_seconds reached");
        return true;
      }
      if (sequence_ == sent) {  // ended, and this viewer has everything
        *ended = status_;
        return true;
      }
      for (const Slot& slot : slots_) {
        if (slot.sequence > sent) events.emplace_back(slot.sequence, slot.event);
      }
      sent = sequence_;
    }
    std::sort(events.begin(), events.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [sequence, event] : events) {
      const bool header = !event->with_header.empty() && event->header_epoch != header_epoch;
      if (!write(header ? event->with_header : event->text)) return false;
      header_epoch = event->header_epoch;
    }
  }
}

FeedTicket::~FeedTicket() { feed_->Leave(); }

std::unique_ptr<FeedTicket> FeedRegistry::Join(const std::string& key, const std::function<FeedSource()>& open) {
  std::lock_guard lock(mutex_);
  for (auto it = feeds_.begin(); it != feeds_.end();) it = it->second.expired() ? feeds_.erase(it) : std::next(it);
  if (auto running = feeds_[key].lock(); running && running->Join()) return std::make_unique<FeedTicket>(running);
  std::shared_ptr<EventFeed> feed(new EventFeed(open()));
  feed->Join();
  feed->Start();
  feeds_[key] = feed;
  return std::make_unique<FeedTicket>(feed);
}

}  // namespace graspsim::rpc
