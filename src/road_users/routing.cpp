#include "road_users/routing.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace convoy::road_users {
namespace odr = convoy::opendrive;

namespace {

// Appends r to out; a segment going on along out's last lane from where it ends extends it.
void append(odr::LaneRoute& out, const odr::LaneRoute& r) {
  for (const auto& seg : r.segments) {
    if (!out.segments.empty() && !seg.lane_change && seg.lane == out.segments.back().lane &&
        std::abs(seg.s_from - out.segments.back().s_to) < 1e-9) {
      out.segments.back().s_to = seg.s_to;  // the same lane on
    } else {
      out.segments.push_back(seg);
    }
  }
  out.length += r.length;
  out.cost += r.cost;
  out.lane_changes += r.lane_changes;
  for (const auto& j : r.junctions) {
    if (out.junctions.empty() || out.junctions.back() != j) out.junctions.push_back(j);
  }
}

odr::RouteSegment segment_at(const odr::LaneGraph& graph, odr::LaneIndex lane, double s_from,
                             double s_to) {
  const odr::LaneNode& n = graph.lane(lane);
  odr::RouteSegment seg;
  seg.lane = lane;
  seg.road_id = n.road->id;
  seg.lane_id = n.lane_id;
  seg.junction = n.junction;
  seg.s_from = s_from;
  seg.s_to = s_to;
  return seg;
}

}  // namespace

odr::LaneRoute onward(const odr::LaneGraph& graph, odr::LaneIndex lane, double s, double length,
                      std::mt19937_64& rng, bool* open) {
  odr::LaneRoute r;
  odr::LaneIndex cur = lane;
  double cs = s;
  *open = false;
  for (int guard = 0; guard < 10000; ++guard) {
    const odr::LaneNode& n = graph.lane(cur);
    odr::RouteSegment seg =
        segment_at(graph, cur, std::clamp(cs, n.s0, n.s1), n.forward ? n.s1 : n.s0);
    if (n.s1 > n.s0) r.length += std::abs(seg.s_to - seg.s_from) / (n.s1 - n.s0) * n.length;
    if (n.junction != "-1" && (r.junctions.empty() || r.junctions.back() != n.junction))
      r.junctions.push_back(n.junction);
    r.segments.push_back(std::move(seg));
    if (r.length >= length) {
      *open = true;
      break;
    }
    std::vector<odr::LaneIndex> next;
    for (odr::LaneIndex l : graph.successors(cur)) {
      if (graph.lane(l).drivable()) next.push_back(l);
    }
    if (next.empty()) break;  // a dead end: the route ends there
    cur = next.size() == 1 ? next[0] : next[rng() % next.size()];
    const odr::LaneNode& nn = graph.lane(cur);
    cs = nn.forward ? nn.s0 : nn.s1;
  }
  r.cost = r.length;
  return r;
}

std::optional<odr::LaneRoute> route_from(const RoutePlan& plan, const std::vector<Goal>& goals,
                                         bool onward_after, odr::LaneIndex lane, double s,
                                         size_t first, bool* open_end, size_t* failed) {
  odr::LaneRoute out;
  odr::LaneIndex cur = lane;
  double cs = s;
  for (size_t i = first; i < goals.size(); ++i) {
    auto r = plan.graph.route(cur, cs, goals[i].lane, goals[i].s);
    if (!r) {
      *failed = i;
      return std::nullopt;
    }
    append(out, *r);
    cur = goals[i].lane;
    cs = goals[i].s;
  }
  *open_end = false;
  if (onward_after) append(out, onward(plan.graph, cur, cs, plan.length, plan.rng, open_end));
  // At its goal already: a route of no length there.
  if (out.segments.empty()) out.segments.push_back(segment_at(plan.graph, cur, cs, cs));
  return out;
}

odr::LaneRoute plan_from(const RoutePlan& plan, std::vector<Goal>& goals, bool& onward_after,
                         odr::LaneIndex lane, double s, bool* open_end) {
  size_t failed = 0;
  if (auto r = route_from(plan, goals, onward_after, lane, s, 0, open_end, &failed)) return *r;
  // Its goals cannot be reached from here any more: the lane graph onward.
  goals.clear();
  onward_after = true;
  return *route_from(plan, goals, onward_after, lane, s, 0, open_end, &failed);
}

std::optional<odr::LaneRoute> route_keeping(const RoutePlan& plan, const std::vector<Goal>& goals,
                                            bool onward_after, odr::LaneIndex target, double s,
                                            int shift, bool* open_end) {
  const odr::LaneGraph& graph = plan.graph;
  if (goals.empty()) {
    if (!onward_after) return std::nullopt;
    return onward(graph, target, s, plan.length, plan.rng, open_end);
  }
  odr::RouteOptions keep;
  keep.lane_changes = false;
  std::optional<odr::LaneRoute> route;
  const Goal& g = goals.front();
  const odr::LaneNode& dest = graph.lane(g.lane);
  const odr::LaneIndex dest2 = graph.find(dest.road->id, dest.lane_id + shift, g.s);
  if (dest2 != odr::kNoLane) route = graph.route(target, s, dest2, g.s, keep);
  if (!route) route = graph.route(target, s, g.lane, g.s);
  if (route && !route->segments.empty() && (goals.size() > 1 || onward_after)) {
    // On through the other goals (and onward) from where it reaches the first.
    size_t failed = 0;
    const auto& end = route->segments.back();
    auto rest = route_from(plan, goals, onward_after, end.lane, end.s_to, 1, open_end, &failed);
    if (!rest) return std::nullopt;
    for (auto& seg : rest->segments) {
      if (seg.lane == route->segments.back().lane &&
          std::abs(seg.s_from - route->segments.back().s_to) < 1e-9 && !seg.lane_change) {
        route->segments.back().s_to = seg.s_to;
      } else {
        route->segments.push_back(seg);
      }
    }
  }
  return route;
}

std::vector<double> goal_arcs(const odr::LaneGraph& graph, const Path& path,
                              const std::vector<Goal>& goals) {
  std::vector<double> arcs;
  size_t lo = 0;
  for (const Goal& g : goals) {
    const odr::LaneNode& n = graph.lane(g.lane);
    const double s = std::clamp(g.s, n.s0 + 1e-3, std::max(n.s0 + 1e-3, n.s1 - 1e-3));
    const odr::WorldPose w = graph.world_pose(n.road->id, n.lane_id, s);
    const auto pr = path.project(w.x, w.y, lo);
    arcs.push_back(std::isfinite(pr.d2) ? pr.arc : path.length());
    lo = pr.index;
  }
  return arcs;
}

odr::LaneRoute extended(const RoutePlan& plan, const Path& path, double arc, bool* open) {
  // The route so far from 30 m behind it, and the lane graph onward from its end.
  odr::LaneRoute route = path.route;
  size_t lo = 0, keep_from = 0;
  for (size_t i = 0; i < route.segments.size(); ++i) {
    const auto& g = route.segments[i];
    const double dir = g.s_to >= g.s_from ? 1.0 : -1.0;
    const double probe = std::abs(g.s_to - g.s_from) > 2e-3 ? g.s_to - dir * 1e-3 : g.s_to;
    const odr::WorldPose w = plan.graph.world_pose(g.road_id, g.lane_id, probe);
    const auto pr = path.project(w.x, w.y, lo);
    lo = pr.index;
    if (pr.arc >= arc - 30.0) break;
    keep_from = i + 1;
  }
  if (keep_from > 0) keep_from -= 1;  // one more behind, for the lane change blends
  route.segments.erase(route.segments.begin(), route.segments.begin() + keep_from);
  if (!route.segments.empty()) route.segments.front().lane_change = false;
  const odr::RouteSegment last = route.segments.back();
  const odr::LaneRoute more = onward(plan.graph, last.lane, last.s_to, plan.length, plan.rng, open);
  for (const auto& seg : more.segments) {
    if (seg.lane == route.segments.back().lane &&
        std::abs(seg.s_from - route.segments.back().s_to) < 1e-9) {
      route.segments.back().s_to = seg.s_to;
    } else {
      route.segments.push_back(seg);
    }
  }
  return route;
}

}  // namespace convoy::road_users
