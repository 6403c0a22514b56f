// The Python module `convoy_live` that the coordinator's interpreter gives the transceiver,
// preprocessing and status functions: `convoy_live.publish(topic, obj)` sends a JSON object to
// the viewers of a live run (`convoy run --live`) on /convoy/metrics or /convoy/infractions,
// and into the recording (`--record`) under the same topics; without either it does nothing
// and returns False. `convoy_live.enabled()` says which.
// Publishing reads `obj` and changes nothing the run computes or writes.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace convoy::python {

inline constexpr const char* kMetricsTopic = "/convoy/metrics";
inline constexpr const char* kInfractionsTopic = "/convoy/infractions";

// Where publish() goes: (topic, the object as JSON text, the simulated time of the function's
// cycle) -> sent. Null: nowhere (publish returns False).
using LivePublisher =
    std::function<bool(const std::string& topic, const std::string& json, int64_t time_ns)>;
// publish() goes to each slot's publisher: the live server's and the recording's.
enum class PublisherSlot { kLive, kRecording };
void set_live_publisher(LivePublisher publisher, PublisherSlot slot = PublisherSlot::kLive);
// The simulated time of the cycle whose functions run (FunctionRuntime sets it).
void set_live_time(int64_t time_ns);

}  // namespace convoy::python
