#include "opendrive/sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace convoy::opendrive {
namespace {

double wrap_angle(double a) {
  a = std::remainder(a, 2 * std::numbers::pi);
  return a;
}

bool is_cubic(const std::vector<CubicRecord>& records, double s) {
  if (records.empty()) return false;
  auto it = std::upper_bound(records.begin(), records.end(), s,
                             [](double v, const CubicRecord& r) { return v < r.start; });
  const CubicRecord& r = it == records.begin() ? *it : *(it - 1);
  return r.c != 0 || r.d != 0;
}

// Lateral or vertical shape changes non-linearly at s.
bool varies_at(const Road& road, double s) {
  if (is_cubic(road.lane_offsets, s) || is_cubic(road.elevation_profile, s)) return true;
  if (road.sections.empty()) return false;
  for (const Lane& lane : road.sections[road.section_index(s)].lanes) {
    if (is_cubic(lane.widths, s)) return true;
  }
  return false;
}

// Pose on a lane centre in the direction of travel.
Pose2 travel_pose(const Road& road, const RouteLeg& leg, double s) {
  Pose2 p = road.lane_point(s, leg.lane_id, 0.5);
  if (!leg.forward) {
    p.heading += std::numbers::pi;
    p.curvature = -p.curvature;
  }
  p.heading = wrap_angle(p.heading);
  return p;
}

// Fills route.length and route.points.
void sample_legs(const Network& network, Route& route, double ds) {
  if (!(ds > 0)) throw std::runtime_error(network.source + ": sampling step must be > 0");
  struct Knot {
    size_t leg;
    double s;
    double ell;  // lane-centre arc length from the route's start
  };
  SamplingOptions fine;
  fine.max_curve_segment = 0.25;
  fine.max_straight_segment = 1.0;
  fine.max_varying_segment = 0.25;
  std::vector<Knot> knots;
  double ell = 0;
  Pose2 last;
  for (size_t i = 0; i < route.legs.size(); ++i) {
    const RouteLeg& leg = route.legs[i];
    const Road& road = network.road(leg.road_id);
    std::vector<double> stations = road_stations(road, 0, road.length, fine);
    if (!leg.forward) std::reverse(stations.begin(), stations.end());
    for (double s : stations) {
      const Pose2 p = road.lane_point(s, leg.lane_id, 0.5);
      if (!knots.empty()) ell += std::hypot(p.x - last.x, p.y - last.y);
      knots.push_back({i, s, ell});
      last = p;
    }
  }
  route.length = ell;
  // A lane width or offset polynomial that runs away (a typo in `d`) makes the lane centre
  // millions of metres long: refuse before allocating the points.
  if (!std::isfinite(ell) || ell / ds > kMaxSamples) {
    throw std::runtime_error(network.source + ": road " + route.legs.front().road_id + " lane " +
                             std::to_string(route.legs.front().lane_id) + ": a route of " +
                             std::to_string(ell) + " m sampled every " + std::to_string(ds) +
                             " m has too many points (lane width or offset out of range?)");
  }
  std::vector<double> targets;
  if (route.closed) {
    const double n = std::max(1.0, std::round(ell / ds));
    for (int k = 0; k < static_cast<int>(n); ++k) targets.push_back(ell * k / n);
  } else {
    for (double t = 0; t < ell - 1e-6; t += ds) targets.push_back(t);
    targets.push_back(ell);
  }
  route.points.clear();
  size_t j = 0;
  for (double t : targets) {
    while (j + 2 < knots.size() && knots[j + 1].ell <= t) ++j;
    const Knot& a = knots[j];
    const Knot& b = knots[std::min(j + 1, knots.size() - 1)];
    const Knot* at = &a;
    double s = a.s;
    if (b.leg != a.leg) {
      at = t >= b.ell ? &b : &a;  // a near-zero hop between roads: take the nearer end
      s = at->s;
    } else if (b.ell > a.ell) {
      s = a.s + (b.s - a.s) * std::clamp((t - a.ell) / (b.ell - a.ell), 0.0, 1.0);
    }
    const RouteLeg& leg = route.legs[at->leg];
    route.points.push_back(travel_pose(network.road(leg.road_id), leg, s));
  }
}

// Throws, naming the file, unless the road has the lane.
void check_lane(const Network& network, const Road& road, int lane_id) {
  try {
    road.lane_borders(0.0, lane_id);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(network.source + ": " + e.what());
  }
}

}  // namespace

std::vector<double> road_stations(const Road& road, double s0, double s1,
                                  const SamplingOptions& options) {
  if (road.plan_view.empty()) throw std::runtime_error("road " + road.id + ": no geometry");
  s0 = std::clamp(s0, 0.0, road.length);
  s1 = std::clamp(s1, s0, road.length);
  std::vector<double> breaks = {s0, s1};
  auto add = [&](double s) {
    if (s > s0 && s < s1) breaks.push_back(s);
  };
  for (const Geometry& g : road.plan_view) add(g.s);
  for (const CubicRecord& r : road.lane_offsets) add(r.start);
  for (const CubicRecord& r : road.elevation_profile) add(r.start);
  for (const LaneSection& sec : road.sections) {
    add(sec.s);
    for (const Lane& lane : sec.lanes) {
      for (const CubicRecord& r : lane.widths) add(r.start);
      for (const RoadMark& m : lane.road_marks) add(m.start);
    }
  }
  std::sort(breaks.begin(), breaks.end());
  std::vector<double> out;
  for (size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double a = breaks[i], b = breaks[i + 1];
    if (b - a < 1e-6) continue;
    const Geometry& g =
        *std::prev(std::upper_bound(road.plan_view.begin() + 1, road.plan_view.end(), 0.5 * (a + b),
                                    [](double v, const Geometry& geom) { return v < geom.s; }));
    const double kappa = g.max_abs_curvature(a - g.s, b - g.s);
    double step = options.max_straight_segment;
    if (kappa > 1e-9) {
      step = std::min(options.max_curve_segment, std::sqrt(8 * options.chord_tolerance / kappa));
    }
    if (varies_at(road, 0.5 * (a + b))) step = std::min(step, options.max_varying_segment);
    const double segments = std::ceil((b - a) / step - 1e-9);
    if (!(segments + static_cast<double>(out.size()) <= kMaxSamples)) {
      throw std::runtime_error("road " + road.id + ": too long or too curved to sample (" +
                               std::to_string(b - a) + " m in steps of " + std::to_string(step) +
                               " m)");
    }
    const int n = std::max(1, static_cast<int>(segments));
    for (int k = 0; k < n; ++k) out.push_back(a + (b - a) * k / n);
  }
  out.push_back(s1);
  return out;
}

std::vector<Pose2> sample_lane_centre(const Network& network, const std::string& road_id,
                                      int lane_id, double ds) {
  Route route;
  const Road& road = network.road(road_id);
  check_lane(network, road, lane_id);
  route.legs.push_back({road_id, lane_id, true});
  sample_legs(network, route, ds);
  return std::move(route.points);
}

Route plan_route(const Network& network, const std::string& start_road, int lane_id,
                 Travel travel) {
  const Road& first = network.road(start_road);
  check_lane(network, first, lane_id);
  bool forward = true;
  if (travel == Travel::kDrivingDirection && lane_id != 0) {
    forward = first.rule == "LHT" ? lane_id > 0 : lane_id < 0;
  }
  Route route;
  route.legs.push_back({start_road, lane_id, forward});
  for (;;) {
    const RouteLeg cur = route.legs.back();
    const Road& road = network.road(cur.road_id);
    const RoadLink& link = cur.forward ? road.successor : road.predecessor;
    const std::string where =
        network.source + ": road " + road.id + (cur.forward ? " successor" : " predecessor");
    if (link.empty()) break;
    if (link.element_type != "road") {
      throw std::runtime_error(where + ": leads into junction " + link.element_id +
                               "; routes through junctions are not supported");
    }
    const Road& next_road = network.road(link.element_id);
    const std::string contact =
        link.contact_point.empty() ? (cur.forward ? "start" : "end") : link.contact_point;
    RouteLeg next{next_road.id, 0, contact == "start"};
    const LaneSection& sec = cur.forward ? road.sections.back() : road.sections.front();
    const Lane* lane = sec.find_lane(cur.lane_id);
    const std::optional<int> lane_link =
        lane ? (cur.forward ? lane->successor : lane->predecessor) : std::nullopt;
    next.lane_id =
        lane_link ? *lane_link : (next.forward == cur.forward ? cur.lane_id : -cur.lane_id);
    const LaneSection& next_sec =
        next.forward ? next_road.sections.front() : next_road.sections.back();
    if (next.lane_id == 0 && cur.lane_id != 0) break;  // the lane ends here
    if (!next_sec.find_lane(next.lane_id)) {
      throw std::runtime_error(where + ": road " + next_road.id + " has no lane " +
                               std::to_string(next.lane_id) + " to continue lane " +
                               std::to_string(cur.lane_id));
    }
    const RouteLeg& start = route.legs.front();
    if (next.road_id == start.road_id && next.forward == start.forward &&
        next.lane_id == start.lane_id) {
      route.closed = true;
      break;
    }
    const bool seen = std::any_of(route.legs.begin(), route.legs.end(), [&](const RouteLeg& l) {
      return l.road_id == next.road_id && l.forward == next.forward;
    });
    if (seen) break;
    route.legs.push_back(next);
  }
  if (route.closed) {
    const RouteLeg& a = route.legs.back();
    const RouteLeg& b = route.legs.front();
    const Road& ra = network.road(a.road_id);
    const Road& rb = network.road(b.road_id);
    const Pose2 end = travel_pose(ra, a, a.forward ? ra.length : 0.0);
    const Pose2 start = travel_pose(rb, b, b.forward ? 0.0 : rb.length);
    route.closure_gap = std::hypot(end.x - start.x, end.y - start.y);
    route.closure_heading = wrap_angle(end.heading - start.heading);
  }
  return route;
}

Route sample_route(const Network& network, const std::string& start_road, int lane_id, double ds,
                   Travel travel) {
  Route route = plan_route(network, start_road, lane_id, travel);
  sample_legs(network, route, ds);
  return route;
}

Bounds network_bounds(const Network& network, const SamplingOptions& options) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Bounds b{{inf, inf, inf}, {-inf, -inf, -inf}};
  auto grow = [&b](double x, double y, double z) {
    const std::array<double, 3> p = {x, y, z};
    for (int i = 0; i < 3; ++i) {
      b.min[i] = std::min(b.min[i], p[i]);
      b.max[i] = std::max(b.max[i], p[i]);
    }
  };
  for (const Road& road : network.roads) {
    for (size_t k = 0; k < road.sections.size(); ++k) {
      const LaneSection& sec = road.sections[k];
      for (double s : road_stations(road, sec.s, sec.s_end, options)) {
        const double z = road.elevation(s);
        for (int id : {sec.min_lane_id(), sec.max_lane_id()}) {
          const Pose2 p = road.offset_point(s, road.lane_borders(k, s, id).outer);
          grow(p.x, p.y, z);
        }
      }
    }
  }
  if (network.roads.empty()) b = Bounds{};
  return b;
}

}  // namespace convoy::opendrive
