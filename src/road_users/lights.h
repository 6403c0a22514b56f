// Traffic lights as a driver reads them: the state of each signal, whether the light of a lane
// holds one at its stop line, and where on its path it stops for the next light.
#pragma once

#include <functional>
#include <map>
#include <string>

#include "opendrive/lane_graph.h"
#include "road_users/path.h"

namespace convoy::road_users {

enum class Light { kGreen, kYellow, kRed, kRedYellow, kOff };

// The state of each signal by its OpenDRIVE id; a signal not in it is green.
using LightStates = std::map<std::string, Light, std::less<>>;

// Whether one whose front is at front_s on `lane` waits at a red (or red-yellow) traffic
// light of that lane: its front has not passed the light's stop line by more than 0.5 m.
bool red_for(const opendrive::LaneGraph& graph, const LightStates& lights,
             opendrive::LaneIndex lane, double front_s);

// The gap from `front` (the front bumper's arc on `path`) to the stop line of the next light
// on the path within `radius` m, when that light says stop: red or red-yellow, or yellow when
// it can stop comfortably (the gap exceeds speed^2 / (2 b)). Only the next light counts, and
// a stop line passed by up to 0.5 m is still ahead (the gap is then negative); +inf when it
// need not stop.
double stop_line_gap(const Path& path, const LightStates& lights, double front, double speed,
                     double b, double radius);

}  // namespace convoy::road_users
