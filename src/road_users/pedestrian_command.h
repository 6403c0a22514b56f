// The pedestrian's command contract: one step's JSON command from the scenario engine to a
// pedestrian (docs/road_users.md, "Commands"), checked once into a PedestrianCommand value.
// Keys: time_ns, speed {speed, target_speed, acceleration}, route {positions}, trajectory
// {x, y, z, yaw, speed} (timed) or {polyline, length}, teleport {x, y, z, yaw, speed}; `lane` is
// an error. A command that breaks it throws CommandError naming the key.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "opendrive/lane_graph.h"
#include "road_users/command_parts.h"
#include "road_users/path.h"

namespace convoy::road_users {

// One step's command. Each part overrides its control domain for that step.
struct PedestrianCommand : PathCommand {
  std::optional<double> speed;  // its walking speed
};

// Checks command `j` (keys named from `where`, the datapack's name) and returns its value. Its
// route positions must be within 20 m of a lane of `graph` (messages name
// graph.network().source). Throws CommandError.
PedestrianCommand parse_pedestrian_command(const nlohmann::json& j, const std::string& where,
                                           const opendrive::LaneGraph& graph);

}  // namespace convoy::road_users
