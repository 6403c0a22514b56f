// The synchronous protocol's decisions (sync.h).
#include "sync.h"

#include <cstdio>

namespace convoy::ros_bridge {

SyncVerdict judge(int64_t step_ns, int64_t stamp_ns, bool arrived_since_publish) {
  if (stamp_ns == 0) return arrived_since_publish ? SyncVerdict::kAnswers : SyncVerdict::kEarlier;
  return stamp_ns >= step_ns ? SyncVerdict::kAnswers : SyncVerdict::kLate;
}

std::string type_mismatch(const std::string& topic, const std::string& master_type,
                          const std::string& expected_type) {
  if (master_type.empty() || master_type == "*" || master_type == expected_type) return {};
  return "topic " + topic + " is " + master_type + " on the master; the bridge expects " +
         expected_type;
}

std::string timeout_message(const std::string& topic, int64_t step_ns, double timeout_s,
                            const std::string& expected_type, const TopicOnMaster& known,
                            int late_messages) {
  char head[256];
  std::snprintf(head, sizeof head, "no message on %s for the step at t = %.9g s within %g s",
                topic.c_str(), static_cast<double>(step_ns) * 1e-9, timeout_s);
  std::string text = head;
  if (std::string mismatch = type_mismatch(topic, known.type, expected_type); !mismatch.empty()) {
    text += ": " + mismatch;
  } else if (known.publishers.empty()) {
    text += ": nothing publishes " + topic;
  } else {
    text += ": published by";
    for (size_t i = 0; i < known.publishers.size(); ++i)
      text += (i ? ", " : " ") + known.publishers[i];
    text += known.connected == 0
                ? ", but the bridge is connected to none of them (a node that died without "
                  "unregistering?)"
                : ", which did not answer /clock = t (a message stamped t or later, or "
                  "unstamped)";
  }
  if (late_messages > 0) {
    text += "; " + std::to_string(late_messages) + " message" + (late_messages > 1 ? "s" : "") +
            " stamped before t dropped as late";
  }
  return text;
}

}  // namespace convoy::ros_bridge
