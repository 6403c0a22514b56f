#include "road_users/pedestrian_command.h"

namespace convoy::road_users {
using nlohmann::json;

namespace {

using command_parts::check_object;
using command_parts::fail;
using command_parts::number;

double parse_speed(const std::string& key, const json& v) {
  check_object(key, v, {"speed", "target_speed", "acceleration"});
  const double speed = command_parts::speed_of(key, v, "");
  if (v.contains("target_speed")) number(key, v, "target_speed");
  if (v.contains("acceleration")) number(key, v, "acceleration");
  return speed;
}

}  // namespace

PedestrianCommand parse_pedestrian_command(const json& j, const std::string& where,
                                           const opendrive::LaneGraph& graph) {
  PedestrianCommand c;
  const command_parts::PathParts how{command_parts::parse_point_list, false, ""};
  command_parts::parse_path_command(
      j, where, graph, how, c, [&](const std::string& key, const std::string& k, const json& v) {
        if (k == "speed") {
          c.speed = parse_speed(key, v);
        } else if (k == "lane") {
          fail(key,
               "a pedestrian has no lane to change to (a pedestrian_agent takes speed, route, "
               "trajectory and teleport)");
        } else {
          fail(key, "unknown key (time_ns, speed, route, trajectory, teleport)");
        }
      });
  if (c.timed && c.speed)
    fail(where + ".trajectory", "a timed trajectory sets the speed too: give it alone");
  if (c.teleport && (c.timed || c.polyline))
    fail(where + ".teleport", "give teleport or trajectory, not both");
  return c;
}

}  // namespace convoy::road_users
