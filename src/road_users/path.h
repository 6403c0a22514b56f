// A road user's path: poses a fixed spacing apart along a route on the lane graph (or along a
// polyline), with their arc lengths, the stop lines of the traffic lights it passes and the
// junctions it crosses. Lookups by arc length and projection of a point onto it.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "opendrive/lane_graph.h"

namespace convoy::road_users {

// Points in the plane, [x, y] (a commanded route or trajectory).
using Points = std::vector<std::array<double, 2>>;

struct Path {
  std::vector<opendrive::Pose2> poses;
  // Arc length at each pose; each step at least the straight distance between its two poses
  // (project skips poses on that bound).
  std::vector<double> arc;
  opendrive::LaneRoute route;
  std::vector<std::pair<double, std::string>> stops;  // (arc of stop line, signal id), by arc
  struct Crossing {
    std::string junction;
    double enter = 0, exit = 0;  // arcs
  };
  std::vector<Crossing> crossings;  // junctions crossed, in order

  double length() const { return arc.empty() ? 0 : arc.back(); }
  // Pose at arc length a, interpolated between the poses (clamped to the ends).
  opendrive::Pose2 at(double a) const;
  // The first pose at arc length a or beyond (poses.size() past the end).
  size_t index_at(double a) const;
  // Projection of (x, y) onto the path, by the nearest pose among poses [lo, hi): its index,
  // the arc and the signed lateral offset (left positive) in that pose's frame, and the squared
  // distance to that pose (+inf, arc 0, when the range is empty). `hint`: a pose likely near
  // the point (only speed depends on it, not the result).
  struct Proj {
    double arc = 0, lateral = 0, d2 = INFINITY;
    size_t index = 0;
  };
  Proj project(double x, double y, size_t lo = 0, size_t hi = SIZE_MAX,
               size_t hint = SIZE_MAX) const;
  // Appends `more` to the poses, each arc the last one's plus the straight distance to it;
  // a pose within 1e-6 m of the last one is skipped.
  void append(const std::vector<opendrive::Pose2>& more);
};

// The path along `route`, poses `ds` m apart, with the stop lines of the traffic lights that
// apply to its lanes and the runs of its segments inside junctions.
Path make_path(const opendrive::LaneGraph& graph, const opendrive::LaneRoute& route, double ds);

// The path along a polyline, at most `ds` m between poses, each heading along its segment
// (no route, stops or crossings). Repeated points are skipped; one point alone (or all the
// same) gives a single pose there, heading from (from_x, from_y) towards it.
Path polyline_path(const Points& points, double ds, double from_x, double from_y);

}  // namespace convoy::road_users
