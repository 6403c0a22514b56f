// The bridge's subscriptions (inbox.h).
#include "inbox.h"

#include <ros/subscribe_options.h>
#include <ros/transport_hints.h>

#include <algorithm>
#include <boost/make_shared.hpp>
#include <chrono>

#include "conversions.h"

namespace convoy::ros_bridge {

namespace {

constexpr uint32_t kQueueSize = 100;
constexpr double kConnectionCheck = 0.05;  // s between checks of SyncTopic's publishers
constexpr auto kConnectionSettle = std::chrono::milliseconds(250);

// Calls a callback with its epoch set on the queue.
class EpochCallback final : public ros::CallbackInterface {
 public:
  EpochCallback(ros::CallbackInterfacePtr inner, uint64_t epoch, EpochQueue* queue)
      : inner_(std::move(inner)), epoch_(epoch), queue_(queue) {}
  CallResult call() override {
    queue_->set_calling_epoch(epoch_);
    return inner_->call();
  }
  bool ready() override { return inner_->ready(); }

 private:
  ros::CallbackInterfacePtr inner_;
  uint64_t epoch_;
  EpochQueue* queue_;
};

int64_t stamp_of(const convoy_msgs::Control& m) { return int64_t(m.header.stamp.toNSec()); }
int64_t stamp_of(const geometry_msgs::TwistStamped& m) { return int64_t(m.header.stamp.toNSec()); }
int64_t stamp_of(const geometry_msgs::Twist&) { return 0; }
nlohmann::json json_of(const convoy_msgs::Control& m) { return control_json(m); }
nlohmann::json json_of(const geometry_msgs::TwistStamped& m) { return twist_stamped_json(m); }
nlohmann::json json_of(const geometry_msgs::Twist& m) { return twist_json(m); }

}  // namespace

void EpochQueue::addCallback(const ros::CallbackInterfacePtr& callback, uint64_t removal_id) {
  ros::CallbackQueue::addCallback(boost::make_shared<EpochCallback>(callback, epoch_.load(), this),
                                  removal_id);
}

Inbox::Inbox(ros::NodeHandle& node, const BridgeConfig& config) : synchronous_(config.synchronous) {
  for (const Subscription& s : config.subscribe) {
    if (s.topic == config.sync_topic) sync_index_ = topics_.size();
    topics_.push_back(Topic{s, {}, {}, false});
  }
  for (size_t i = 0; i < topics_.size(); ++i) {
    switch (topics_[i].sub.type) {
      case InType::kControl:
        subscribe<convoy_msgs::Control>(node, i);
        break;
      case InType::kTwist:
        subscribe<geometry_msgs::Twist>(node, i);
        break;
      case InType::kTwistStamped:
        subscribe<geometry_msgs::TwistStamped>(node, i);
        break;
    }
  }
}

template <class M>
void Inbox::subscribe(ros::NodeHandle& node, size_t index) {
  ros::SubscribeOptions options;
  options.template init<M>(topics_[index].sub.topic, kQueueSize,
                           [this, index](const boost::shared_ptr<const M>& m) {
                             receive(index, stamp_of(*m), json_of(*m));
                           });
  options.callback_queue = &queue_;
  options.transport_hints = ros::TransportHints().tcpNoDelay();
  topics_[index].subscriber = node.subscribe(options);
}

void Inbox::receive(size_t index, int64_t stamp_ns, nlohmann::json value) {
  if (synchronous_ && index == sync_index_) {
    switch (judge(step_ns_, stamp_ns, queue_.calling_epoch() >= step_epoch_)) {
      case SyncVerdict::kLate:
        ++late_;
        return;
      case SyncVerdict::kAnswers:
        answered_ = true;
        break;
      case SyncVerdict::kEarlier:
        break;
    }
  }
  topics_[index].latest = std::move(value);
  topics_[index].has = true;
}

void Inbox::begin_step(int64_t step_ns) {
  step_ns_ = step_ns;
  step_epoch_ = queue_.begin_epoch();
  step_publishers_ = sync_publishers();
  answered_ = false;
  late_ = 0;
}

void Inbox::poll() { queue_.callAvailable(ros::WallDuration(0)); }

bool Inbox::wait(double timeout_s, const std::function<void()>& republish) {
  poll();
  if (!synchronous_ || answered_) return true;
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  // A publisher that connects to SyncTopic while the step waits may have answered before the
  // connection was up (ROS drops what it publishes to nobody): the step publishes again when
  // it connects, and once more when the connection has settled.
  uint32_t seen = step_publishers_;
  bool settle_pending = false;
  auto settle_at = Clock::now();
  while (!answered_) {
    const double left = std::chrono::duration<double>(deadline - Clock::now()).count();
    if (left <= 0) return false;
    queue_.callAvailable(ros::WallDuration(std::min(left, kConnectionCheck)));
    if (answered_) break;
    const uint32_t now = sync_publishers();
    if (now > seen) {
      republish();
      settle_pending = true;
      settle_at = Clock::now() + kConnectionSettle;
    } else if (settle_pending && Clock::now() >= settle_at) {
      republish();
      settle_pending = false;
    }
    seen = now;
  }
  return true;
}

bool Inbox::wait_for_publishers(uint32_t count, double timeout_s) {
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (sync_publishers() < count) {
    if (Clock::now() >= deadline) return false;
    queue_.callAvailable(ros::WallDuration(0.01));
  }
  return true;
}

const nlohmann::json* Inbox::latest(const std::string& topic) const {
  for (const Topic& t : topics_)
    if (t.sub.topic == topic) return t.has ? &t.latest : nullptr;
  return nullptr;
}

uint32_t Inbox::sync_publishers() const {
  return topics_.empty() ? 0 : topics_[sync_index_].subscriber.getNumPublishers();
}

void Inbox::clear() {
  for (Topic& t : topics_) {
    t.latest = nullptr;
    t.has = false;
  }
}

}  // namespace convoy::ros_bridge
