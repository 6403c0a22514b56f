// A road vehicle's behaviour, step by step: its description (parameters and route, fixed once
// read), its state (a separate value, replaced at reset) and the step from one state to the
// next given what it perceives (neighbours and lights, acted on ReactionTime late), the
// weather it drives in and the scenario's command for the step.
//
// Longitudinal: IDM on the leader ahead on its path, a red (or stoppable yellow) light's stop
// line and a junction to wait at; lateral: pure pursuit moved as a kinematic bicycle; lane
// changes by MOBIL; routes on the lane graph through its goals, or onward by Seed; commands
// (road_users/command.h) override a control domain for the step they are given in. The
// vehicle_agent engine and the pooled host drive it; no process, transport or Python here.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "opendrive/lane_graph.h"
#include "road_users/command.h"
#include "road_users/idm.h"
#include "road_users/lights.h"
#include "road_users/mobil.h"
#include "road_users/neighbours.h"
#include "road_users/path.h"
#include "road_users/routing.h"
#include "road_users/weather.h"

namespace convoy::road_users {

inline constexpr double kVehicleSampleDs = 0.5;      // m between the path's poses
inline constexpr double kVehicleOnwardLength = 600;  // m of lane graph planned ahead onward

// What a vehicle is and where it goes: fixed once read from its config.
struct VehicleDescription {
  std::string name;                             // its id (its own is skipped among neighbours)
  std::string command_key;                      // names its commands in errors ("command")
  std::string model, category;                  // as published
  const opendrive::LaneGraph* graph = nullptr;  // the map (outlives the description)
  Idm idm;                                      // as configured (the weather adapts a copy)
  Mobil mobil;
  double limit_factor = 0, max_decel = 9;
  bool lane_changes = true, yielding = true, weather_adaptation = true;
  double reaction_s = 0, radius = 100, start_s = 0, initial_speed = 0;
  bool respawn = false;
  double respawn_delay_s = 2.0;
  double length = 4.5, width = 1.8, height = 1.5, wheelbase = 2.7, rear_overhang = 0.9;
  opendrive::LaneRoute initial_route;
  std::vector<Goal> initial_goals;  // points its route passes
  bool initial_onward = false;      // after them the lane graph onward (else the route ends)
  bool initial_open_end = false;    // the route ends where the lane graph goes on
  std::optional<opendrive::Pose2> start_pose;
  std::mt19937_64 initial_rng;  // onward choices, after the initial route's

  // The front bumper's distance ahead of the rear axle (its reference point on the path).
  double front_offset() const { return 0.5 * length + (0.5 * length - rear_overhang); }
};

// What it perceived at one time.
struct VehicleSnapshot {
  int64_t time_ns = 0;
  std::shared_ptr<const Neighbours> neighbours;  // null: none received yet
  std::shared_ptr<const LightStates> lights;
};

// A lane command under way: the path is the target lane's, the agent `lateral` m left of it.
struct LaneRun {
  bool active = false;
  std::string road;
  int lane = 0, from_lane = 0;
  double d_from = 0;  // the from lane's centre, left of the target lane's (m)
  double e0 = 0;      // the agent's offset from the from lane's centre when it began
  double progress = 0, lateral = 0;
  int side = 0;  // +1 to the left, -1 to the right
};

// Where it is and what it does: the value a step changes and `reset` replaces.
struct VehicleState {
  int64_t time_ns = 0;
  Path path;
  size_t cursor = 0;  // index of the nearest path pose
  double arc = 0;     // rear axle's arc along path
  double x = 0, y = 0, yaw = 0, v = 0, acc = 0, yaw_rate = 0;
  bool absent = false;
  int64_t absent_since_ns = 0;
  opendrive::Pose2 initial_path_start{};
  int changing = 0;  // +1 left, -1 right while a lane change is under way
  int64_t next_mobil_ns = 0;
  Driving driving;  // the IDM it drives with (the weather's adaptation of the description's)
  // Perception: stamped with the time each arrived.
  std::deque<VehicleSnapshot> inputs;
  std::shared_ptr<const Neighbours> last_neighbours;
  std::shared_ptr<const LightStates> last_lights;
  // Route: the points still to pass (with their arcs on path), whether the route goes on
  // along the lane graph after them (else it ends: absent), and whether path ends where the
  // lane graph goes on (onward: it is extended).
  std::vector<Goal> goals;
  std::vector<double> goal_arcs;
  bool onward = false, open_end = false;
  std::mt19937_64 rng;  // onward choices
  // Commands.
  std::optional<VehicleCommand> command;  // for the coming step
  std::optional<double> commanded_acc;
  LaneRun lane_run;
  Points last_route, polyline;
  Path traj_path;
  bool off_path = false;  // a command moved it off path: relocalise when the AI takes over
  bool lost = false;      // no driving lane near: it stops and looks again every second
  int64_t next_look_ns = 0;
  // Warnings raised by the last calls, (key, text), for the host to show once per key.
  std::vector<std::pair<std::string, std::string>> warnings;
};

// Its state at time 0 (at its start, with its initial route; nothing perceived).
VehicleState start_vehicle(const VehicleDescription& d);

// Perception arriving now (either may be null: kept from before).
void perceive(VehicleState& s, std::shared_ptr<const Neighbours> neighbours,
              std::shared_ptr<const LightStates> lights);

// The weather it drives in from now on (with weather_adaptation, else the configured IDM).
void drive_in(const VehicleDescription& d, VehicleState& s, const Weather& weather);

// One step of duration_ns with s.command (consumed); false when it stayed absent (nothing
// new to publish). A command that cannot be carried out (a lane or route that does not exist
// from where it is) throws CommandError naming its key (d.command_key...).
bool step_vehicle(const VehicleDescription& d, VehicleState& s, int64_t duration_ns);

// A driving lane near (x, y) whose direction is within 60 degrees of yaw, else any driving
// lane within max_distance (it turns towards it).
std::optional<opendrive::LanePosition> locate_drivable(const opendrive::LaneGraph& graph, double x,
                                                       double y, double yaw, double max_distance);

}  // namespace convoy::road_users
