// The synchronous protocol's decisions, apart from ROS: which message on SyncTopic answers
// the step at time t, and what the timeout error says.
//
// The step t -> t+dt publishes /clock = t and the sensor data stamped t, then waits for a
// message on SyncTopic that answers it: one stamped t or later (convoy_msgs/Control,
// geometry_msgs/TwistStamped), or an unstamped one (stamp 0, or a geometry_msgs/Twist) that
// arrived after the step began publishing. A stamped message older than t answers an earlier
// step (one that already timed out, or a node that is behind): it is dropped as late.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace convoy::ros_bridge {

enum class SyncVerdict {
  kAnswers,  // answers the step: the wait is over; it is the topic's latest message
  kLate,     // stamped before the step: dropped
  kEarlier,  // unstamped, but arrived before the step began publishing: the topic's latest
             // message, not an answer
};

// `stamp_ns` 0 means unstamped. `arrived_since_publish`: the message reached the bridge after
// the step began publishing.
SyncVerdict judge(int64_t step_ns, int64_t stamp_ns, bool arrived_since_publish);

// What the master knows about the sync topic when the wait times out.
struct TopicOnMaster {
  std::vector<std::string> publishers;  // node names
  std::string type;                     // the topic's type on the master ("" when unknown)
  uint32_t connected = 0;               // publishers the bridge's subscriber is connected to
};

// `no message on TOPIC for the step at t = X s within N s`, then what is known: nothing
// publishes it, its type on the master differs from `expected_type`, or who publishes it.
std::string timeout_message(const std::string& topic, int64_t step_ns, double timeout_s,
                            const std::string& expected_type, const TopicOnMaster& known,
                            int late_messages);

// `topic T is A on the master; the bridge expects B`, or "" when the types agree (or the
// master does not know the topic).
std::string type_mismatch(const std::string& topic, const std::string& master_type,
                          const std::string& expected_type);

}  // namespace convoy::ros_bridge
