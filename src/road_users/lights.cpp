#include "road_users/lights.h"

#include <algorithm>
#include <cmath>

namespace convoy::road_users {

bool red_for(const opendrive::LaneGraph& graph, const LightStates& lights,
             opendrive::LaneIndex lane, double front_s) {
  const bool forward = graph.lane(lane).forward;
  for (const auto& info : graph.signals()) {
    if (!info.traffic_light || !info.signal) continue;
    if (std::find(info.lanes.begin(), info.lanes.end(), lane) == info.lanes.end()) continue;
    const auto it = lights.find(info.signal->id);
    if (it == lights.end() || (it->second != Light::kRed && it->second != Light::kRedYellow))
      continue;
    // Past its stop line (it went on yellow, or waits for the junction): not held by it.
    const double stop_s = info.signal->s;
    if (forward ? front_s > stop_s + 0.5 : front_s < stop_s - 0.5) continue;
    return true;
  }
  return false;
}

double stop_line_gap(const Path& path, const LightStates& lights, double front, double speed,
                     double b, double radius) {
  for (const auto& [stop_arc, id] : path.stops) {
    const double g = stop_arc - front;
    if (g < -0.5) continue;  // passed
    if (g > radius) break;
    const auto it = lights.find(id);
    if (it == lights.end()) break;  // green: go (only the next light counts)
    bool stop = it->second == Light::kRed || it->second == Light::kRedYellow;
    if (it->second == Light::kYellow) stop = g > speed * speed / (2 * b);
    return stop ? g : INFINITY;  // only the next light counts
  }
  return INFINITY;
}

}  // namespace convoy::road_users
