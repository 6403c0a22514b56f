#include "road_users/command.h"

#include <cmath>
#include <cstdint>
#include <utility>

#include "opendrive/network.h"

namespace convoy::road_users {
namespace odr = convoy::opendrive;
using nlohmann::json;

namespace {

using command_parts::check_object;
using command_parts::fail;
using command_parts::number;

const char* const kNoReversing = " (reversing is not modelled)";

double speed_of(const std::string& key, const json& v) {
  return command_parts::speed_of(key, v, kNoReversing);
}

VehicleCommand::Speed parse_speed(const std::string& key, const json& v) {
  check_object(key, v, {"speed", "target_speed", "acceleration"});
  VehicleCommand::Speed sp;
  sp.speed = speed_of(key, v);
  if (v.contains("target_speed")) number(key, v, "target_speed");
  if (v.contains("acceleration")) sp.acceleration = number(key, v, "acceleration");
  return sp;
}

// v[n]: a non-zero integer lane id that `road` has in some section.
int lane_id(const std::string& key, const json& v, const char* n, const odr::Road& road) {
  if (!v.contains(n) || !v[n].is_number_integer() || v[n].get<int64_t>() == 0)
    fail(key + "." + n, "expected a non-zero integer lane id, got " +
                            (v.contains(n) ? v[n].dump() : std::string("nothing")));
  const int id = v[n].get<int>();
  bool found = false;
  for (const auto& sec : road.sections) found = found || sec.find_lane(id) != nullptr;
  if (!found) fail(key + "." + n, "road " + road.id + " has no lane " + std::to_string(id));
  return id;
}

VehicleCommand::Lane parse_lane(const std::string& key, const json& v, const odr::Network& net) {
  check_object(key, v, {"road", "lane", "from_lane", "offset", "progress"});
  VehicleCommand::Lane ln;
  if (!v.contains("road") || !v["road"].is_string())
    fail(key + ".road", "expected the road's id as a string");
  ln.road = v["road"].get<std::string>();
  const odr::Road* road = net.find_road(ln.road);
  if (!road) fail(key + ".road", "no road " + ln.road + " in " + net.source);
  ln.lane = lane_id(key, v, "lane", *road);
  ln.from_lane = v.contains("from_lane") ? lane_id(key, v, "from_lane", *road) : ln.lane;
  ln.offset = v.contains("offset") ? number(key, v, "offset") : 0.0;
  ln.progress = v.contains("progress") ? number(key, v, "progress") : 1.0;
  if (ln.progress < 0 || ln.progress > 1)
    fail(key + ".progress", "must be in [0, 1], got " + v["progress"].dump());
  return ln;
}

Points at_least_one(const std::string& key, const json& v) { return parse_points(key, v, 1); }

// The parts that cannot be given together.
void check_combination(const std::string& where, const VehicleCommand& c) {
  if (c.timed && (c.speed || c.lane))
    fail(where + ".trajectory", "a timed trajectory sets both speed and lane: give it alone");
  if (c.polyline && c.lane)
    fail(where + ".trajectory", "both lane and trajectory steer: give one of them");
  if (c.teleport && (c.timed || c.polyline))
    fail(where + ".teleport", "give teleport or trajectory, not both");
}

}  // namespace

VehicleCommand parse_vehicle_command(const json& j, const std::string& where,
                                     const odr::LaneGraph& graph) {
  VehicleCommand c;
  const command_parts::PathParts how{at_least_one, true, kNoReversing};
  command_parts::parse_path_command(
      j, where, graph, how, c, [&](const std::string& key, const std::string& k, const json& v) {
        if (k == "speed") {
          c.speed = parse_speed(key, v);
        } else if (k == "lane") {
          c.lane = parse_lane(key, v, graph.network());
        } else {
          fail(key, "unknown key (time_ns, speed, lane, route, trajectory, teleport)");
        }
      });
  check_combination(where, c);
  return c;
}

}  // namespace convoy::road_users
