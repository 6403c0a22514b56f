// The JSON lane lookups (query.h): one reply per request.
#include "opendrive/query.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "worldgen/markings.h"

namespace convoy::opendrive {
namespace {

nlohmann::json stop_lines_json(const LaneGraph& g) {
  nlohmann::json out = nlohmann::json::array();
  for (const SignalInfo& info : g.signals()) {
    if (!info.traffic_light) continue;
    const Signal& sig = *info.signal;
    const Road& road = g.network().road(info.road_id);
    const double s = std::clamp(sig.s, 0.0, road.length);
    const Pose2 ref = road.reference(s);
    auto [t_min, t_max] = convoy::worldgen::signal_span(road, sig);
    double heading = ref.heading;
    const bool against = sig.orientation == "-";
    if (against) {
      heading += std::numbers::pi;
      std::tie(t_min, t_max) = std::pair{-t_max, -t_min};
    }
    const Pose2 entry = road.reference(against ? 0.0 : road.length);
    out.push_back({{"id", sig.id},
                   {"road", road.id},
                   {"x", ref.x},
                   {"y", ref.y},
                   {"heading", heading},
                   {"t_min", t_min},
                   {"t_max", t_max},
                   {"entry_x", entry.x},
                   {"entry_y", entry.y}});
  }
  return out;
}

nlohmann::json points_json(const std::vector<Pose2>& pts) {
  nlohmann::json out = nlohmann::json::array();
  for (const Pose2& p : pts) out.push_back({p.x, p.y, p.heading});
  return out;
}

double angle_diff(double a, double b) {
  double d = std::fmod(a - b, 2 * std::numbers::pi);
  if (d > std::numbers::pi) d -= 2 * std::numbers::pi;
  if (d < -std::numbers::pi) d += 2 * std::numbers::pi;
  return std::fabs(d);
}

// Heading of the lane's driving direction at its start / end.
double lane_heading(const LaneGraph& g, LaneIndex i, bool at_end) {
  const LaneNode& n = g.lane(i);
  const double s = (at_end == n.forward) ? n.s1 - 1e-6 : n.s0 + 1e-6;
  return g.world_pose(n.road->id, n.lane_id, s).heading;
}

nlohmann::json query_follow(const LaneGraph& g, const nlohmann::json& q) {
  const std::string road = q.at("road").get<std::string>();
  const int lane = q.at("lane").get<int>();
  double s = q.at("s").get<double>();
  const double length = q.at("length").get<double>();
  const double ds = q.value("ds", 2.0);
  if (!(length > 0) || !(ds > 0)) throw std::runtime_error("length and ds must be > 0");
  LaneIndex cur = g.require(road, lane, s);
  LaneRoute route;
  nlohmann::json lanes = nlohmann::json::array();
  double left = length;
  for (int guard = 0; guard < 1000 && left > 1e-9; ++guard) {
    const LaneNode& n = g.lane(cur);
    const double end = n.forward ? n.s1 : n.s0;
    const double avail = std::fabs(end - s);
    const double take = std::min(avail, left);
    RouteSegment seg;
    seg.lane = cur;
    seg.road_id = n.road->id;
    seg.lane_id = n.lane_id;
    seg.junction = n.junction;
    seg.s_from = s;
    seg.s_to = n.forward ? s + take : s - take;
    if (take > 1e-9 || route.segments.empty()) {
      route.segments.push_back(seg);
      route.length += take;
      if (lanes.empty() || lanes.back() != nlohmann::json({n.road->id, n.lane_id}))
        lanes.push_back({n.road->id, n.lane_id});
    }
    left -= take;
    if (left <= 1e-9) break;
    LaneIndex best = kNoLane;
    double best_turn = 1e9;
    const double h_end = lane_heading(g, cur, true);
    for (LaneIndex nx : g.successors(cur)) {
      if (!g.lane(nx).drivable()) continue;
      const double turn = angle_diff(lane_heading(g, nx, false), h_end) +
                          0.5 * angle_diff(lane_heading(g, nx, true), h_end);
      if (turn < best_turn - 1e-9) best_turn = turn, best = nx;
    }
    if (best == kNoLane) break;  // dead end
    cur = best;
    const LaneNode& nn = g.lane(cur);
    s = nn.forward ? nn.s0 : nn.s1;
  }
  return {{"points", points_json(g.sample(route, ds))}, {"length", route.length}, {"lanes", lanes}};
}

}  // namespace

nlohmann::json query(const LaneGraph& g, const nlohmann::json& q) {
  const std::string op = q.at("op").get<std::string>();
  if (op == "pose") {
    const WorldPose p = g.world_pose(q.at("road").get<std::string>(), q.at("lane").get<int>(),
                                     q.at("s").get<double>(), q.value("offset", 0.0));
    return {{"x", p.x}, {"y", p.y}, {"z", p.z}, {"heading", p.heading}};
  }
  if (op == "locate") {
    std::optional<double> yaw;
    if (q.contains("yaw") && !q["yaw"].is_null()) yaw = q["yaw"].get<double>();
    const auto p = g.locate(q.at("x").get<double>(), q.at("y").get<double>(), yaw,
                            q.value("max_distance", 5.0));
    if (!p) return {{"found", false}};
    const LaneNode& n = g.lane(p->lane);
    return {{"found", true},
            {"road", p->road_id},
            {"lane", p->lane_id},
            {"s", p->s},
            {"t", p->t},
            {"road_t", p->road_t},
            {"z", g.network().road(p->road_id).surface_z(p->s, p->road_t)},
            {"heading", p->heading},
            {"distance", p->distance},
            {"type", n.type},
            {"junction", n.junction}};
  }
  if (op == "follow") return query_follow(g, q);
  if (op == "route") {
    const auto& f = q.at("from");
    const auto& t = q.at("to");
    const LaneIndex a =
        g.require(f.at(0).get<std::string>(), f.at(1).get<int>(), f.at(2).get<double>());
    const LaneIndex b =
        g.require(t.at(0).get<std::string>(), t.at(1).get<int>(), t.at(2).get<double>());
    RouteOptions options;
    options.lane_changes = q.value("lane_changes", true);
    const auto r = g.route(a, f.at(2).get<double>(), b, t.at(2).get<double>(), options);
    if (!r) throw std::runtime_error("no route between the two lane positions");
    return {{"points", points_json(g.sample(*r, q.value("ds", 2.0)))}, {"length", r->length}};
  }
  if (op == "info") {
    nlohmann::json roads = nlohmann::json::array(), signals = nlohmann::json::array();
    for (const auto& r : g.network().roads)
      roads.push_back({{"id", r.id}, {"length", r.length}, {"junction", r.junction}});
    for (const auto& s : g.signals())
      if (s.traffic_light) signals.push_back(s.signal->id);
    return {{"roads", roads}, {"signals", signals}};
  }
  if (op == "stop_lines") return {{"stop_lines", stop_lines_json(g)}};
  throw std::runtime_error("unknown op '" + op +
                           "' (pose, locate, follow, route, info, stop_lines)");
}

}  // namespace convoy::opendrive
