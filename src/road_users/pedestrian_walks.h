// A walker's planner on the lane graph: walks along sidewalk lanes (either direction), the
// shortest plan from one sidewalk point to another over them and at most one crosswalk (or a
// mid-block crossing near it), straight legs between points, and the path it walks with the
// roads it crosses on it (where it is on the road, and the signals that rule the crossing).
// Used by pedestrian_behaviour.h and the pedestrian_agent engine's config.
#pragma once

#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "opendrive/lane_graph.h"
#include "road_users/path.h"

namespace convoy::road_users {

inline constexpr double kWalkSampleDs = 0.25;  // m between a walk's poses
inline constexpr double kSignalNear = 12.0;    // m along the road: a signal belongs to a crosswalk

// A road crossed on a walk.
struct WalkCrossing {
  std::string road_id, crosswalk;  // crosswalk id, empty mid-block
  double start = 0, end = 0;       // arcs of the leg (sidewalk centre to sidewalk centre)
  double enter = 0, exit = 0;      // arcs where it is on the road
  std::vector<std::string> ped_signals, veh_signals;
};

// The path a walker walks: the library's poses and arcs, with the roads it crosses on it.
struct WalkPath : Path {
  std::vector<WalkCrossing> road_crossings;
};

// A point on a sidewalk lane.
struct Spot {
  opendrive::LaneIndex lane = opendrive::kNoLane;
  double s = 0;
};

// One crossing of a road at s, from the sidewalk `from` to the sidewalk `to`.
struct CrossPlan {
  std::string road_id, crosswalk;
  Spot from, to;
};

struct WalkPlan {
  std::optional<opendrive::LaneRoute> before, after;  // walks; `after` only with a crossing
  std::optional<CrossPlan> cross;
  double length = INFINITY;
};

// Along sidewalks from a to b (either direction, no lane changes).
std::optional<opendrive::LaneRoute> walk(const opendrive::LaneGraph& graph, Spot a, Spot b);
// The shortest plan from `from` to `to`: a walk, or walk, crosswalk, walk (only that
// crosswalk when `only`: never the plain walk then).
WalkPlan plan_walk(const opendrive::LaneGraph& graph, Spot from, Spot to,
                   const opendrive::Crosswalk* only);
// The crossing `c` moved `factor` m along its road away from the road's near end, between the
// same sidewalks; nullopt where they are not there.
std::optional<CrossPlan> mid_block(const opendrive::LaneGraph& graph, const CrossPlan& c,
                                   double factor);
// The path of a plan, with its crossing (on-road part and the signals within kSignalNear).
WalkPath make_walk_path(const opendrive::LaneGraph& graph, const WalkPlan& p);
// The nearest sidewalk lane within 50 m.
std::optional<opendrive::LanePosition> nearest_sidewalk(const opendrive::LaneGraph& graph, double x,
                                                        double y);
// A straight leg from a to b appended to `path`; the part of it off the sidewalks is a
// crossing (with gap acceptance).
void append_leg(const opendrive::LaneGraph& graph, WalkPath& path, double ax, double ay, double bx,
                double by);
// From (x, y): to the nearest sidewalk, then to `dest` over sidewalks and crosswalks, or
// along the sidewalks onward in the direction `yaw` (forks drawn from rng); false without a
// sidewalk near. *join: the arc past the corner where it joins the sidewalk.
bool walk_path_from(const opendrive::LaneGraph& graph, WalkPath& path, double x, double y,
                    double yaw, const std::optional<Spot>& dest, std::mt19937_64& rng,
                    double* join = nullptr);
// A commanded route's walk, appended to `path`: from (x, y) facing `yaw`, straight legs through
// `via` in order (append_leg: their parts off the sidewalks are crossings), then walk_path_from
// the last point (facing along the last leg) to `dest` or onward; false, the path ending at the
// last point, without a sidewalk near it. The pedestrian_agent's and the pooled walkers' rule.
bool walk_through(const opendrive::LaneGraph& graph, WalkPath& path, double x, double y, double yaw,
                  const Points& via, const std::optional<Spot>& dest, std::mt19937_64& rng,
                  double* join = nullptr);

// A commanded polyline's walk: poses about kWalkSampleDs apart through `points`, each heading
// along its segment (the last point's as the segment before it; `yaw` for a single point).
WalkPath polyline_walk(const Points& points, double yaw);
// One step along a polyline walk `t` from (x, y) facing `yaw`, at v m/s for dt s: towards the
// point 0.5 m ahead of its pose nearest (x, y) (its end when that is past it), stopping at its
// end. Where it gets to, its heading (`yaw` when it does not move) and how far it moved.
struct WalkStep {
  double x = 0, y = 0, yaw = 0, moved = 0;
};
WalkStep step_along(const WalkPath& t, double x, double y, double yaw, double v, double dt);

}  // namespace convoy::road_users
