// convoy-odr query's "stop_lines": where traffic meets each traffic light. For every dynamic
// signal of type 1000001: its id and road, the reference line's point at the signal's s with
// the heading of the traffic it is for (the road's, turned round for orientation "-"), the
// lateral span of its lanes along that heading (t_min, t_max, left positive), and the end of
// its road that traffic drives into (the junction's edge).
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "opendrive/lane_graph.h"
#include "worldgen/markings.h"

namespace odr = convoy::opendrive;

nlohmann::json stop_lines_json(const odr::LaneGraph& g) {
  nlohmann::json out = nlohmann::json::array();
  for (const odr::SignalInfo& info : g.signals()) {
    if (!info.traffic_light) continue;
    const odr::Signal& sig = *info.signal;
    const odr::Road& road = g.network().road(info.road_id);
    const double s = std::clamp(sig.s, 0.0, road.length);
    const odr::Pose2 ref = road.reference(s);
    auto [t_min, t_max] = convoy::worldgen::signal_span(road, sig);
    double heading = ref.heading;
    const bool against = sig.orientation == "-";
    if (against) {
      heading += std::numbers::pi;
      std::tie(t_min, t_max) = std::pair{-t_max, -t_min};
    }
    const odr::Pose2 entry = road.reference(against ? 0.0 : road.length);
    out.push_back({{"id", sig.id},
                   {"road", road.id},
                   {"x", ref.x},
                   {"y", ref.y},
                   {"heading", heading},
                   {"t_min", t_min},
                   {"t_max", t_max},
                   {"entry_x", entry.x},
                   {"entry_y", entry.y}});
  }
  return out;
}
