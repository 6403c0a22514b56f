// Config parts both agents read alike (agent_config.h).
#include "road_users/agent_config.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "road_users/command_parts.h"

namespace convoy::road_users {

std::pair<std::string, int> parse_lane_ref(const std::string& key, const nlohmann::json& v) {
  if (!v.is_string()) throw CommandError(key, "expected \"ROAD:LANE\"");
  const std::string s = v.get<std::string>();
  const auto colon = s.rfind(':');
  if (colon == std::string::npos || colon == 0)
    throw CommandError(key, "expected \"ROAD:LANE\", got \"" + s + "\"");
  try {
    size_t used = 0;
    const int lane = std::stoi(s.substr(colon + 1), &used);
    if (used != s.size() - colon - 1 || lane == 0) throw std::invalid_argument("lane");
    return {s.substr(0, colon), lane};
  } catch (const std::exception&) {
    throw CommandError(key, "expected \"ROAD:LANE\" with a non-zero lane id, got \"" + s + "\"");
  }
}

opendrive::Pose2 parse_start_pose(const nlohmann::json& sp) {
  for (const auto& [k, v] : sp.items()) {
    if (k != "x" && k != "y" && k != "yaw")
      throw CommandError("StartPose", "unknown key \"" + k + "\" (x, y, yaw)");
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      throw CommandError("StartPose." + k, "expected a number");
  }
  if (!sp.contains("x") || !sp.contains("y") || !sp.contains("yaw"))
    throw CommandError("StartPose", "expected numbers \"x\", \"y\" and \"yaw\"");
  return {sp["x"].get<double>(), sp["y"].get<double>(), sp["yaw"].get<double>()};
}

std::string nearest_lane_text(const opendrive::LaneGraph& graph,
                              const std::optional<opendrive::LanePosition>& loc) {
  if (!loc) return "no road within 50 m";
  char d[160];
  std::snprintf(d, sizeof d, "nearest lane %s:%d (%s) %.2f m away", loc->road_id.c_str(),
                loc->lane_id, graph.lane(loc->lane).type.c_str(), loc->distance);
  return d;
}

}  // namespace convoy::road_users
