// What the live server has still to send to one client: a bounded queue of data messages
// that drops the oldest when full (and counts them), beside an unbounded queue of control
// messages (serverInfo, advertise, status), which are few and never dropped. The simulation's
// thread pushes, the server's thread pops: the simulation never waits for a slow viewer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

namespace convoy::live {

struct OutMessage {
  bool binary = false;
  std::string head;                         // sent before `body` (a messageData header)
  std::shared_ptr<const std::string> body;  // shared by every client that gets it
  size_t size() const { return head.size() + (body ? body->size() : 0); }
};

struct QueueLimits {
  size_t max_messages = 4096;
  size_t max_bytes = size_t{64} << 20;
};

class SendQueue {
 public:
  explicit SendQueue(QueueLimits limits = {}) : limits_(limits) {}

  // A data message; drops the oldest data messages while over a limit (a message larger than
  // max_bytes alone still goes, alone).
  void push_data(OutMessage m);
  void push_control(OutMessage m);
  // Control messages first, then data in order; nothing when empty.
  std::optional<OutMessage> pop();
  bool empty() const;

  uint64_t dropped() const;  // data messages dropped so far
  uint64_t pushed() const;   // data messages pushed so far
  size_t bytes() const;      // queued data bytes

 private:
  QueueLimits limits_;
  mutable std::mutex mutex_;
  std::deque<OutMessage> control_, data_;
  size_t bytes_ = 0;
  uint64_t dropped_ = 0, pushed_ = 0;
};

}  // namespace convoy::live
