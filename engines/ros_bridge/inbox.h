// The messages the bridge subscribes to (Subscribe), as the latest JSON value per topic, and
// the synchronous wait for the message that answers a step (sync.h).
//
// Callbacks go to the inbox's own callback queue, called only from wait() / poll() on the
// engine's thread: no spinner threads touch its state. The queue notes when each message
// arrived relative to the steps (an epoch counter), which ros::Time cannot tell once the
// master's /use_sim_time is true.
#pragma once

#include <ros/callback_queue.h>
#include <ros/node_handle.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bridge_config.h"
#include "sync.h"

namespace convoy::ros_bridge {

// A callback queue that tags each callback with the epoch in which its message arrived.
class EpochQueue : public ros::CallbackQueue {
 public:
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t removal_id = 0) override;
  // A new epoch begins (a step begins publishing); returns its number.
  uint64_t begin_epoch() { return ++epoch_; }
  // The epoch of the message whose callback is being called.
  uint64_t calling_epoch() const { return calling_; }
  void set_calling_epoch(uint64_t epoch) { calling_ = epoch; }

 private:
  std::atomic<uint64_t> epoch_{0};
  uint64_t calling_ = 0;
};

class Inbox {
 public:
  // Subscribes to every topic of config.subscribe (TCP_NODELAY, queue of 100 messages).
  Inbox(ros::NodeHandle& node, const BridgeConfig& config);

  // The step at `step_ns` begins publishing: later messages may answer it.
  void begin_step(int64_t step_ns);
  // Calls the callbacks that are waiting; with Synchronous, waits until a message on SyncTopic
  // answers the step. False when none did within `timeout_s`. Calls `republish` (the step's
  // messages again) when a publisher of SyncTopic connects during the wait, and 250 ms later.
  bool wait(double timeout_s, const std::function<void()>& republish);
  // Waits until SyncTopic's subscriber is connected to `count` publishers; false on timeout.
  bool wait_for_publishers(uint32_t count, double timeout_s);
  // Calls the callbacks that are waiting, without waiting.
  void poll();
  // The latest message on `topic` as JSON, nullptr before the first (or an unknown topic).
  const nlohmann::json* latest(const std::string& topic) const;
  // Messages on SyncTopic dropped as late since the last begin_step.
  int late() const { return late_; }
  // Publishers connected to SyncTopic's subscriber.
  uint32_t sync_publishers() const;
  void clear();

 private:
  struct Topic {
    Subscription sub;
    ros::Subscriber subscriber;
    nlohmann::json latest;
    bool has = false;
  };
  template <class M>
  void subscribe(ros::NodeHandle& node, size_t index);
  void receive(size_t index, int64_t stamp_ns, nlohmann::json value);

  EpochQueue queue_;
  std::vector<Topic> topics_;
  bool synchronous_;
  size_t sync_index_ = 0;
  int64_t step_ns_ = 0;
  uint64_t step_epoch_ = 0;
  uint32_t step_publishers_ = 0;  // SyncTopic's publishers connected when the step began
  bool answered_ = false;
  int late_ = 0;
};

}  // namespace convoy::ros_bridge
