// A live run's channels beyond the datapacks, and its control by the viewers:
// - /convoy/control (client -> server, json, schema convoy.Control): {"command": "pause"},
//   {"command": "resume"} or {"command": "step"} (one loop cycle, then paused) hold the loop
//   at its loop::PauseGate; anything else gets a status error to that client;
// - /convoy/status {"paused", "time_ns"}: on each change, and to each new subscriber;
// - /convoy/metrics: the summary fields the functions published (convoy_live.publish, e.g.
//   convoy_bench.run_files.update_summary), merged into the latest, with "time_ns";
// - /convoy/infractions: one message per infraction event a function published.
#pragma once

#include <cstdint>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "live/server.h"
#include "loop/pause_gate.h"

namespace convoy::live {

inline constexpr const char* kControlTopic = "/convoy/control";
inline constexpr const char* kStatusTopic = "/convoy/status";
inline constexpr const char* kMetricsTopic = "/convoy/metrics";
inline constexpr const char* kInfractionsTopic = "/convoy/infractions";

// A /convoy/control message.
struct ControlCommand {
  enum class Kind { kPause, kResume, kStep, kInvalid } kind = Kind::kInvalid;
  std::string error;  // kInvalid: why, for the client
};
ControlCommand parse_control(std::string_view payload);

// {"paused": ..., "time_ns": ...}
std::string run_status_json(bool paused, int64_t time_ns);

class RunControl {
 public:
  // Adds the channels to `server` and accepts /convoy/control for `gate`. Both must outlive
  // this object.
  RunControl(LiveServer& server, loop::PauseGate& gate);
  ~RunControl();
  RunControl(const RunControl&) = delete;
  RunControl& operator=(const RunControl&) = delete;

  // A function's message (python/live_module.h). False for another topic or a payload that is
  // not a JSON object. Any thread.
  bool publish(const std::string& topic, const std::string& json, int64_t time_ns);

  uint64_t commands() const;   // control commands obeyed
  uint64_t published() const;  // metrics and infraction messages sent

 private:
  std::string on_control(std::string_view payload);

  LiveServer& server_;
  loop::PauseGate& gate_;
  uint32_t status_ = 0, metrics_ = 0, infractions_ = 0;
  mutable std::mutex mutex_;
  nlohmann::json latest_metrics_ = nlohmann::json::object();
  uint64_t commands_ = 0, published_ = 0;
};

}  // namespace convoy::live
