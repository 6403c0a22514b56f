#include "live/send_queue.h"

namespace convoy::live {

void SendQueue::push_data(OutMessage m) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++pushed_;
  bytes_ += m.size();
  data_.push_back(std::move(m));
  while (data_.size() > 1 && (data_.size() > limits_.max_messages || bytes_ > limits_.max_bytes)) {
    bytes_ -= data_.front().size();
    data_.pop_front();
    ++dropped_;
  }
}

void SendQueue::push_control(OutMessage m) {
  std::lock_guard<std::mutex> lock(mutex_);
  control_.push_back(std::move(m));
}

std::optional<OutMessage> SendQueue::pop() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!control_.empty()) {
    OutMessage m = std::move(control_.front());
    control_.pop_front();
    return m;
  }
  if (data_.empty()) return std::nullopt;
  OutMessage m = std::move(data_.front());
  data_.pop_front();
  bytes_ -= m.size();
  return m;
}

bool SendQueue::empty() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return control_.empty() && data_.empty();
}

uint64_t SendQueue::dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

uint64_t SendQueue::pushed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return pushed_;
}

size_t SendQueue::bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bytes_;
}

}  // namespace convoy::live
