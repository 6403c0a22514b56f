// Internal to vehicle_behaviour.cpp and vehicle_manoeuvres.cpp: one step's work on a vehicle's
// state, as the parts of that step (not for other users: see vehicle_behaviour.h).
#pragma once

#include <string>
#include <utility>

#include "road_users/command.h"
#include "road_users/vehicle_behaviour.h"

namespace convoy::road_users::vehicle_detail {

struct Stepper {
  const VehicleDescription& d;
  VehicleState& s;

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw CommandError(key, what);
  }
  void warn_once(const std::string& key, const std::string& text) {
    s.warnings.emplace_back(key, text);
  }
  Path make_path(const opendrive::LaneRoute& route) const {
    return road_users::make_path(*d.graph, route, kVehicleSampleDs);
  }
  // Routing on the lane graph (road_users/routing.h) with its goals, onward, open_end and rng
  // (the onward choices, drawn from Seed).
  RoutePlan plan() { return {*d.graph, kVehicleOnwardLength, s.rng}; }
  std::optional<opendrive::LaneRoute> route_from(opendrive::LaneIndex lane, double at, size_t first,
                                                 size_t* failed) {
    return road_users::route_from(plan(), s.goals, s.onward, lane, at, first, &s.open_end, failed);
  }
  opendrive::LaneRoute plan_from(opendrive::LaneIndex lane, double at) {
    return road_users::plan_from(plan(), s.goals, s.onward, lane, at, &s.open_end);
  }
  std::optional<opendrive::LaneRoute> route_keeping(opendrive::LaneIndex target, double at,
                                                    int shift) {
    return road_users::route_keeping(plan(), s.goals, s.onward, target, at, shift, &s.open_end);
  }
  void compute_goal_arcs() { s.goal_arcs = goal_arcs(*d.graph, s.path, s.goals); }
  Observer observer() const { return {d.name, s.x, s.y, s.yaw, s.v, d.radius}; }
  const VehicleSnapshot* perceived() const;
  // Respawn: its start is free (nobody within its length + 6 m of it in its latest view).
  bool start_free() const;

  // vehicle_behaviour.cpp: the step and its parts.
  bool step(int64_t duration_ns);
  void restart();
  bool place(const VehicleCommand& cmd, double dt);
  bool follow_commands(const std::optional<VehicleCommand>& cmd);
  std::pair<double, double> longitudinal(const std::optional<VehicleCommand>& cmd, bool on_poly,
                                         double dt);
  void lateral(const std::optional<VehicleCommand>& cmd, bool on_poly, double v_new, double dt);
  void advance_on_path(double dt);
  double desired_speed() const;
  std::pair<double, double> stop_ahead(const Path& drive, size_t cursor, double front,
                                       bool on_poly) const;

  // vehicle_manoeuvres.cpp: lane changes, re-planning and the commands' manoeuvres.
  void consider_lane_change();
  void set_path(const opendrive::LaneRoute& route);
  bool relocalise();
  void apply_route(const Points& positions);
  void begin_lane(const VehicleCommand::Lane& c);
  void set_polyline(const Points& points);
  void extend();
};

}  // namespace convoy::road_users::vehicle_detail
