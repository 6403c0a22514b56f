// A walker's crossing of a road: the vehicles that threaten its crossing line, gap acceptance
// at the curb, the lights that let it go, and how far it may walk once it has stepped onto the
// road (stopping before a vehicle's lane, stepping back out of one).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "road_users/pedestrian_walks.h"

namespace convoy::road_users {

// A straight crossing leg from (ax, ay), along the unit vector (ux, uy), `len` m long.
struct CrossingLeg {
  double ax = 0, ay = 0, ux = 0, uy = 0, len = 0;
};

// A vehicle near the crossing: its reference point, heading, speed and body (length_offset:
// from the reference point to its centre, along its heading).
struct CrossingVehicle {
  double x = 0, y = 0, yaw = 0, speed = 0;
  double length = 0, width = 0, length_offset = 0;
};

// A vehicle moving across the crossing line.
struct CrossingThreat {
  double tta = 0;         // s until its front reaches the line
  double front = 0;       // m from its front to the line, along its heading
  double u = 0;           // where it crosses the line, m from the leg's start
  double half_width = 0;  // half its width (0.9 m when not given)
  double speed = 0;
};

// The threat `v` is to `leg`: none when it moves along the leg (not across), crosses the line
// more than its half width + 1 m beyond the leg's ends, or its back has passed the line.
std::optional<CrossingThreat> crossing_threat(const CrossingLeg& leg, const CrossingVehicle& v);

// The gap is accepted: every threat arrives `gap` s or more from now.
bool gap_accepted(const std::vector<CrossingThreat>& threats, double gap);

// Whether the lights let it step onto the road, from the states of the crossing's pedestrian
// lights and of the crossed road's vehicle lights ("" when the datapack does not give one): the
// pedestrian lights that are on must be green; with none on, the vehicle lights that are on
// must be red.
bool walker_lights_allow(const std::vector<std::string>& ped_states,
                         const std::vector<std::string>& veh_states);

inline constexpr double kCurbWait = 0.3;  // m before the road's edge where a walker waits

// While crossing (committed): the farthest arc it may be at, at most `limit`, from the threats
// to the leg that starts at arc `start`, it being at arc `arc` walking `v_des` m/s.
struct CrossingCaution {
  double stop_distance = 8;       // m: a vehicle's front this near, it waits before its lane
  double step_back_distance = 4;  // m: this near while in its lane, it steps back out
};
double crossing_limit(const std::vector<CrossingThreat>& threats, double start, double arc,
                      double v_des, const CrossingCaution& caution, double limit);

// The farthest arc a walker at `arc` on `path`, walking `v_des` m/s in steps of dt s, may be
// at: the path's end, or where its next crossing lets it go. Within 3 m of the curb it asks
// `may_step_on` (lights, gap), waiting at the curb (kCurbWait before the road) until it says
// yes; it commits (`committed` = the crossing's index) once at the curb with a yes, and from
// then on goes as far as crossing_limit lets it among `threats`.
using CrossingCheck = std::function<bool(const WalkCrossing&)>;
using CrossingThreats = std::function<std::vector<CrossingThreat>(const WalkCrossing&)>;
double path_limit(const WalkPath& path, double arc, double v_des, double dt, size_t& committed,
                  const CrossingCaution& caution, const CrossingCheck& may_step_on,
                  const CrossingThreats& threats);

// The pace a walker at (x, y) heading `yaw`, wanting `v`, may keep behind another walker at
// (ux, uy) heading `uyaw` at `uspeed`: one in its way (within its body's width of its line,
// going its way or standing) closer than `follow_gap` m is not overtaken (its pace, along).
double pace_behind(double x, double y, double yaw, double ux, double uy, double uyaw, double uspeed,
                   double v, double follow_gap);

}  // namespace convoy::road_users
