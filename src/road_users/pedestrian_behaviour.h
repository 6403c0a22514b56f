// A pedestrian's behaviour, step by step: its description (parameters and its walk, fixed once
// read), its state (a separate value, replaced at reset) and the step from one state to the
// next given the road users around it, the lights, the rain and the scenario's command.
//
// It walks the centre of sidewalk lanes along a route (sidewalks in either direction) and
// crosses a road at a crosswalk or, with probability MidBlockProbability, mid-block (the same
// road, MidBlockDistance from the crosswalk, away from the junction). A crossing is a straight
// line from one sidewalk's centre to the other's; the part of it off the sidewalks is "on the
// road".
//
// Before stepping onto the road it waits at the curb until
//   - the light lets it (ObeyLights): at a crosswalk with pedestrian lights (type 1000002 on the
//     crossed road within 12 m of it), while they are green; without them, while every vehicle
//     light (1000001) of the crossed road within 12 m is red (so it crosses when the traffic it
//     crosses is held); no such signal, or a state the datapack does not give: unsignalised;
//   - and every approaching vehicle's time-to-arrival at its crossing line (the vehicle's front
//     along its heading, at its speed) is at least its critical gap.
// While crossing it stops before the next vehicle's lane when a moving vehicle's front is
// within StopDistance of the crossing (or would arrive before it has crossed that lane), and
// steps back out of the lane it is in when one is within StepBackDistance (or would arrive
// before it could clear the lane forwards, and backing out is shorter). Speed (N(Speed, SpeedSd))
// and critical gap (N(CriticalGap, CriticalGapSd)) differ per pedestrian, drawn from Seed, as are
// the mid-block choice and a route when none is given. Deterministic: no wall clock, no other
// randomness.
//
// Commands (pedestrian_command.h) override it for the step they are given in. The
// pedestrian_agent engine drives it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "opendrive/lane_graph.h"
#include "road_users/neighbours.h"
#include "road_users/pedestrian_command.h"
#include "road_users/pedestrian_walks.h"

namespace convoy::road_users {

inline constexpr double kKeepRight = 0.55;  // m right of its path's centre line: walkers pass

// What a pedestrian is and where it walks: fixed once read from its config.
struct PedestrianDescription {
  std::string name;
  std::string lights_key;                       // its lights datapack's name (in a warning)
  const opendrive::LaneGraph* graph = nullptr;  // the map (outlives the description)
  double speed = 1.35, gap = 4.0, stop_distance = 8, step_back_distance = 4;
  double length = 0.5, width = 0.6, height = 1.75, stride = 1.4, radius = 100;
  bool obey_lights = true;
  bool respawn = false;
  double respawn_delay_s = 2.0;
  std::string model;
  WalkPath initial_path;
  std::optional<Spot> dest;  // where its route ends (none: onward)
  std::optional<opendrive::Pose2> start_pose;
  bool initial_idle = false;    // no sidewalk near its StartPose: it stands until commanded
  double initial_kr_from = 0;   // the arc from which it eases over to kKeepRight
  std::mt19937_64 initial_rng;  // onward choices, after the initial walk's
};

// The road users around it (present ones, not itself), in the order received.
struct WalkerNeighbours {
  Neighbours walkers;   // of category "pedestrian"
  Neighbours vehicles;  // the others
};

// Signal id -> state ("red", "green", ...), as the lights datapack gives them.
using SignalStates = std::map<std::string, std::string, std::less<>>;

// Where it is and what it does: the value a step changes and `reset` replaces.
struct PedestrianState {
  int64_t time_ns = 0;
  WalkPath path;
  double arc = 0, v = 0, acc = 0, walked = 0;
  double x = 0, y = 0, yaw = 0, yaw_rate = 0;
  size_t committed = SIZE_MAX;  // index of the crossing it has stepped onto / may step onto
  bool absent = false;
  int64_t absent_since_ns = 0;
  std::shared_ptr<const WalkerNeighbours> neighbours;  // null: none received yet
  std::shared_ptr<const SignalStates> lights;          // null: none received yet
  double rain_factor = 1.0;
  double kr = kKeepRight;     // how far right of the path it walks (0 at a new path's start)
  double kr_from = 0;         // the arc from which it eases over to kKeepRight (on the sidewalk)
  bool idle = false;          // no sidewalk near: it stands until commanded
  bool stand_at_end = false;  // its path does not reach a sidewalk: it stands at its end
  std::mt19937_64 rng;        // onward choices
  std::optional<PedestrianCommand> command;  // for the coming step
  Points last_route, polyline;
  WalkPath traj_path;
  bool off_path = false;  // a command moved it off path: re-plan when the AI takes over
  // Warnings raised by the last calls, (key, text), for the host to show once per key.
  std::vector<std::pair<std::string, std::string>> warnings;
};

// Its state at time 0 (at its start, nothing perceived).
PedestrianState start_pedestrian(const PedestrianDescription& d);

// One step of duration_ns with s.command (consumed); false when it stayed absent (nothing new
// to publish).
bool step_pedestrian(const PedestrianDescription& d, PedestrianState& s, int64_t duration_ns);

// The factor on its walking speed in the weather: 1 + 0.2 precipitation (0..1) in rain.
double rain_factor(double precipitation, bool rain);

}  // namespace convoy::road_users
