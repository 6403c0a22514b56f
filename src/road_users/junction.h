// Junction yielding: first come, first served at the entry of the next junction on a path,
// by arrival time (ties by id), anyone inside blocking, one held by its red light not counted
// and one that can no longer stop for it (whoever drives it) let through.
#pragma once

#include <cstddef>

#include "opendrive/lane_graph.h"
#include "road_users/idm.h"
#include "road_users/lights.h"
#include "road_users/neighbours.h"
#include "road_users/path.h"

namespace convoy::road_users {

// The driver at a junction: where it is on its path and what it can do.
struct Approach {
  const Path* path = nullptr;
  size_t cursor = 0;     // its nearest pose on the path
  double front = 0;      // its front bumper's arc on the path
  double length = 4.5;   // m
  double max_decel = 9;  // m/s^2: it is committed once it cannot stop within this
  Idm idm;               // a and v0 give the arrival times (its own and the others')
};

// The gap from its front to the entry of the next junction on its path when it must wait
// there, else +inf: the junction is farther than me.radius, it is inside already or committed,
// or it is first. Others on its own path (within 1.2 m of it, heading along it within
// 0.5 rad) are IDM's business and not counted; `lights` (null: none seen) tell who waits at a
// red light.
double junction_wait(const opendrive::LaneGraph& graph, const Approach& at, const Observer& me,
                     const Neighbours& around, const LightStates* lights);

}  // namespace convoy::road_users
