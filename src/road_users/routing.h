// Routing on the lane graph: a road user's route through the points it must pass (its goals)
// and, when it goes on after them, along the lane graph onward, each fork's choice drawn from
// its random generator (passed in, so that the same seed gives the same choices).
#pragma once

#include <cstddef>
#include <optional>
#include <random>
#include <vector>

#include "opendrive/lane_graph.h"
#include "road_users/path.h"

namespace convoy::road_users {

// A point its route passes: (lane, s) on the lane graph.
struct Goal {
  opendrive::LaneIndex lane = opendrive::kNoLane;
  double s = 0;
};

// The lane graph onward from (lane, s), at each fork a drivable successor drawn from rng (one
// draw per fork of more than one), until `length` m (*open: true, the lane graph goes on) or a
// dead end (*open: false).
opendrive::LaneRoute onward(const opendrive::LaneGraph& graph, opendrive::LaneIndex lane, double s,
                            double length, std::mt19937_64& rng, bool* open);

// What routes are planned on: the lane graph, how far onward is planned at a time (m) and the
// random generator that draws the forks' choices.
struct RoutePlan {
  const opendrive::LaneGraph& graph;
  double length;
  std::mt19937_64& rng;
};

// A route from (lane, s) through goals[first..] and then, when onward, onward (*open_end: as
// onward()'s *open; false without onward). At a goal already: a route of one segment of no
// length there. nullopt with *failed = the index of the goal it cannot reach (*open_end left
// as it was).
std::optional<opendrive::LaneRoute> route_from(const RoutePlan& plan,
                                               const std::vector<Goal>& goals, bool onward,
                                               opendrive::LaneIndex lane, double s, size_t first,
                                               bool* open_end, size_t* failed);

// The route on from (lane, s): through its goals when it can still reach them, else onward
// (goals cleared, onward set: its goals given up).
opendrive::LaneRoute plan_from(const RoutePlan& plan, std::vector<Goal>& goals, bool& onward,
                               opendrive::LaneIndex lane, double s, bool* open_end);

// After a change into `target` at s (lane ids `shift` from its own): the route keeping that
// lane to its next goal's road when it can (else any route to the goal), then through the
// other goals and onward; onward alone without goals; nullopt when there is none.
std::optional<opendrive::LaneRoute> route_keeping(const RoutePlan& plan,
                                                  const std::vector<Goal>& goals, bool onward,
                                                  opendrive::LaneIndex target, double s, int shift,
                                                  bool* open_end);

// The arcs along `path` at which it passes each goal, in order (each projected from the
// previous one's pose on; the path's length for one it does not come near).
std::vector<double> goal_arcs(const opendrive::LaneGraph& graph, const Path& path,
                              const std::vector<Goal>& goals);

// The route of `path` from 30 m behind `arc` (and one segment more, for the lane change
// blends), then the lane graph onward from its end (*open: as onward()'s).
opendrive::LaneRoute extended(const RoutePlan& plan, const Path& path, double arc, bool* open);

}  // namespace convoy::road_users
