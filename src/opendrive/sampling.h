// Sampling a Network: adaptive stations along a road (for meshes), evenly spaced lane-centre
// waypoints along one road or along a route that follows road links (for controllers and
// traffic), and the network's bounding box.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "opendrive/network.h"

namespace convoy::opendrive {

// Most points one road_stations or sample_* call returns; more throws std::runtime_error (a
// hostile or mistyped file must not take all memory: 100 km at 0.05 m fit).
inline constexpr double kMaxSamples = 2e6;

struct SamplingOptions {
  double max_curve_segment = 0.5;     // m, where the reference line curves
  double max_straight_segment = 5.0;  // m, straight with linear lane widths and offsets
  double max_varying_segment = 1.0;   // m, straight but with cubic widths / offset / elevation
  double chord_tolerance = 0.005;     // m, largest sagitta of a chord on a curve
};

// Road s values in [s0, s1], both ends included, plus every boundary in between (geometries,
// lane sections, width / offset / elevation records, road marks). Spacing adapts to the
// curvature: sqrt(8 tol / kappa), at most max_curve_segment on curves.
std::vector<double> road_stations(const Road& road, double s0, double s1,
                                  const SamplingOptions& options = {});

// Points on the centre of one lane of one road, in the road's s direction, spaced `ds` apart
// along the lane centre (not along the reference line); the last point is the road's end, so
// the last gap may be shorter. Throws for an unknown road or lane or ds <= 0.
std::vector<Pose2> sample_lane_centre(const Network& network, const std::string& road_id,
                                      int lane_id, double ds);

// Which way a route runs along its lane.
enum class Travel {
  kDrivingDirection,    // the lane's traffic direction: with s for right lanes under RHT
  kReferenceDirection,  // always with the start road's s
};

struct RouteLeg {
  std::string road_id;
  int lane_id = 0;
  bool forward = true;  // with the road's s
};

// A route along one lane: the roads it runs through and, from sample_route, its waypoints.
struct Route {
  std::vector<RouteLeg> legs;
  bool closed = false;         // the links lead back to the first leg
  double length = 0;           // along the lane centre (m); sample_route only
  double closure_gap = 0;      // closed: distance from the last leg's end to the first's start
  double closure_heading = 0;  // closed: heading difference there, rad in [-pi, pi]
  std::vector<Pose2> points;   // waypoints, heading in the direction of travel
};

// Starts where the lane enters `start_road` (its s = 0 when travelling with s, its end when
// against) and follows road links from there (successors when travelling with s, predecessors
// against it; contactPoint decides the direction on the next road, lane links the lane) until
// the links end, return to the start (closed) or repeat a road. Throws on links into junctions.
Route plan_route(const Network& network, const std::string& start_road, int lane_id,
                 Travel travel = Travel::kDrivingDirection);

// plan_route plus waypoints on the lane centre. Open routes: spaced ds, ending at the route's
// end. Closed routes: once around, spaced length / round(length / ds) so the gap from the last
// point back to the first is the same as all others (the first point is not repeated).
Route sample_route(const Network& network, const std::string& start_road, int lane_id, double ds,
                   Travel travel = Travel::kDrivingDirection);

struct Bounds {
  std::array<double, 3> min{};
  std::array<double, 3> max{};
};

// Box around every road's outermost lane borders and elevations (road marks and curbs add a
// few centimetres in z that this does not include).
Bounds network_bounds(const Network& network, const SamplingOptions& options = {});

}  // namespace convoy::opendrive
