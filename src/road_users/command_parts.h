// The building blocks of the road users' command contracts (docs/road_users.md, "Commands"),
// shared by the vehicle's and the pedestrian's: the error naming the key, a pose, and the checks
// of objects, numbers, speeds and point lists in the config validator's style.
#pragma once

#include <cstddef>
#include <functional>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "opendrive/lane_graph.h"
#include "road_users/path.h"

namespace convoy::road_users {

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

// A commanded pose {x, y, z, yaw, speed} (z checked, not kept).
struct CommandPose {
  double x = 0, y = 0, yaw = 0;
  std::optional<double> speed;
};

// The parts of a command both road users take: route, trajectory (timed or a polyline),
// teleport.
struct PathCommand {
  using Pose = CommandPose;
  std::optional<Points> route;     // positions to go through
  std::optional<Pose> timed;       // trajectory with a timing: the pose to take
  std::optional<Points> polyline;  // trajectory without: the path to follow
  std::optional<Pose> teleport;
};

// A list of at least `min_points` points [x, y] (or [x, y, z], z dropped) of finite numbers.
// Throws CommandError naming `key` (or `key[i]`).
Points parse_points(const std::string& key, const nlohmann::json& v, size_t min_points);

namespace command_parts {

[[noreturn]] void fail(const std::string& key, const std::string& detail);
// v as JSON, cut to 80 characters (for messages).
std::string shown(const nlohmann::json& v);
// v is an object whose keys are all among `known`.
void check_object(const std::string& key, const nlohmann::json& v,
                  std::initializer_list<const char*> known);
// obj[k], which must be there and a finite number.
double number(const std::string& key, const nlohmann::json& obj, const char* k);
// v["speed"], a number >= 0; `note` follows the message when it is not.
double speed_of(const std::string& key, const nlohmann::json& v, const std::string& note);
// {x, y, z, yaw, speed}, speed required when `speed_needed` (checked as speed_of with `note`).
CommandPose parse_pose(const std::string& key, const nlohmann::json& v, bool speed_needed,
                       const std::string& note);
// A non-empty list of points [x, y] (or [x, y, z]); the message says "a list of points".
Points parse_point_list(const std::string& key, const nlohmann::json& v);

// How a command's point lists are read (parse_point_list, or parse_points with a minimum).
using ListParser = Points (*)(const std::string& key, const nlohmann::json& v);
// Route {positions}: points read by `list`, each within 20 m of a lane of `graph` (a driving
// lane when `driving`; messages name graph.network().source).
Points parse_route(const std::string& key, const nlohmann::json& v,
                   const opendrive::LaneGraph& graph, ListParser list, bool driving);
// Trajectory: {polyline, length} (the polyline read by `list`) into c.polyline, or a timed pose
// {x, y, z, yaw, speed} into c.timed (its speed checked with `note`).
void parse_trajectory(const std::string& key, const nlohmann::json& v, ListParser list,
                      const std::string& note, PathCommand& c);

// How a road user reads the parts of PathCommand.
struct PathParts {
  ListParser list;   // route positions and polylines
  bool driving;      // route positions near a driving lane (else any lane)
  std::string note;  // after "must be >= 0 m/s" in a pose's speed
};
// The key, the part's name and its value of a part other than time_ns, route, trajectory and
// teleport (the road user's own: it reads it or fails).
using OtherPart =
    std::function<void(const std::string& key, const std::string& k, const nlohmann::json& v)>;
// Checks that j is an object of parts (keys named from `where`), reads time_ns, route,
// trajectory and teleport into c as `how` says, and hands the others to `other`, in j's order.
void parse_path_command(const nlohmann::json& j, const std::string& where,
                        const opendrive::LaneGraph& graph, const PathParts& how, PathCommand& c,
                        const OtherPart& other);

}  // namespace command_parts
}  // namespace convoy::road_users
