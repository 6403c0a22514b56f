// The command contract: one step's JSON command from the scenario engine to a vehicle
// (docs/road_users.md, "Commands"), checked once into a VehicleCommand value. Keys: time_ns,
// speed {speed, target_speed, acceleration}, lane {road, lane, from_lane, offset, progress},
// route {positions}, trajectory {x, y, z, yaw, speed} (timed) or {polyline, length}, teleport
// {x, y, z, yaw, speed}. A command that breaks it throws CommandError naming the key.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "opendrive/lane_graph.h"
#include "road_users/path.h"

namespace convoy::road_users {

// One step's command. Each part overrides its control domain for that step.
struct VehicleCommand {
  struct Speed {
    double speed = 0;
    std::optional<double> acceleration;
  };
  struct Lane {
    std::string road;
    int lane = 0, from_lane = 0;      // from_lane: lane when not given
    double offset = 0, progress = 0;  // progress: 1 when not given
  };
  struct Pose {
    double x = 0, y = 0, yaw = 0;
    std::optional<double> speed;
  };
  std::optional<Speed> speed;
  std::optional<Lane> lane;
  std::optional<Points> route;
  std::optional<Pose> timed;       // trajectory with a timing: the pose to take
  std::optional<Points> polyline;  // trajectory without: the path to follow
  std::optional<Pose> teleport;
};

// A command (or part) that breaks the contract: what() is "<key>: <detail>", the key in the
// config validator's style ("command.speed.speed", "command.route.positions[1]").
class CommandError : public std::runtime_error {
 public:
  CommandError(const std::string& key, const std::string& detail)
      : std::runtime_error(key + ": " + detail), key_(key), detail_(detail) {}
  const std::string& key() const { return key_; }
  const std::string& detail() const { return detail_; }

 private:
  std::string key_, detail_;
};

// Checks command `j` (keys named from `where`, the datapack's name) and returns its value. Its
// lanes must exist on `graph`'s roads and its route positions be within 20 m of a driving lane
// (messages name graph.network().source). Throws CommandError.
VehicleCommand parse_vehicle_command(const nlohmann::json& j, const std::string& where,
                                     const opendrive::LaneGraph& graph);

// A list of at least `min_points` points [x, y] (or [x, y, z], z dropped) of finite numbers.
// Throws CommandError naming `key` (or `key[i]`).
Points parse_points(const std::string& key, const nlohmann::json& v, size_t min_points);

}  // namespace convoy::road_users
