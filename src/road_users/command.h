// The command contract: one step's JSON command from the scenario engine to a vehicle
// (docs/road_users.md, "Commands"), checked once into a VehicleCommand value. Keys: time_ns,
// speed {speed, target_speed, acceleration}, lane {road, lane, from_lane, offset, progress},
// route {positions}, trajectory {x, y, z, yaw, speed} (timed) or {polyline, length}, teleport
// {x, y, z, yaw, speed}. A command that breaks it throws CommandError naming the key.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "opendrive/lane_graph.h"
#include "road_users/command_parts.h"
#include "road_users/path.h"

namespace convoy::road_users {

// One step's command. Each part overrides its control domain for that step.
struct VehicleCommand : PathCommand {
  struct Speed {
    double speed = 0;
    std::optional<double> acceleration;
  };
  struct Lane {
    std::string road;
    int lane = 0, from_lane = 0;      // from_lane: lane when not given
    double offset = 0, progress = 0;  // progress: 1 when not given
  };
  std::optional<Speed> speed;
  std::optional<Lane> lane;
};

// Checks command `j` (keys named from `where`, the datapack's name) and returns its value. Its
// lanes must exist on `graph`'s roads and its route positions be within 20 m of a driving lane
// (messages name graph.network().source). Throws CommandError.
VehicleCommand parse_vehicle_command(const nlohmann::json& j, const std::string& where,
                                     const opendrive::LaneGraph& graph);

}  // namespace convoy::road_users
