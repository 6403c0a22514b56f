// A walker's planner (pedestrian_walks.h).
#include "road_users/pedestrian_walks.h"

#include <algorithm>
#include <cmath>

namespace convoy::road_users {
namespace odr = convoy::opendrive;

std::optional<odr::LaneRoute> walk(const odr::LaneGraph& graph, Spot a, Spot b) {
  odr::RouteOptions o;
  o.lane_types = {"sidewalk"};
  o.both_directions = true;
  o.lane_changes = false;
  return graph.route(a.lane, a.s, b.lane, b.s, o);
}

WalkPlan plan_walk(const odr::LaneGraph& graph, Spot from, Spot to, const odr::Crosswalk* only) {
  WalkPlan best;
  if (!only) {
    if (auto w = walk(graph, from, to)) {
      best.before = w;
      best.length = w->length;
    }
  }
  for (const auto& cw : graph.crosswalks()) {
    if (only && &cw != only) continue;
    if (cw.ends[0] == odr::kNoLane || cw.ends[1] == odr::kNoLane) continue;
    for (int d = 0; d < 2; ++d) {
      const Spot a{cw.ends[d], cw.s}, b{cw.ends[1 - d], cw.s};
      auto w1 = walk(graph, from, a);
      if (!w1) continue;
      auto w2 = walk(graph, b, to);
      if (!w2) continue;
      const odr::WorldPose pa = graph.world_pose(cw.road_id, graph.lane(a.lane).lane_id, a.s);
      const odr::WorldPose pb = graph.world_pose(cw.road_id, graph.lane(b.lane).lane_id, b.s);
      const double len = w1->length + w2->length + std::hypot(pb.x - pa.x, pb.y - pa.y);
      if (len < best.length - 1e-9) {
        best.before = w1;
        best.after = w2;
        best.cross = CrossPlan{cw.road_id, cw.id, a, b};
        best.length = len;
      }
    }
  }
  return best;
}

std::optional<CrossPlan> mid_block(const odr::LaneGraph& graph, const CrossPlan& c, double factor) {
  const odr::Road* r = graph.network().find_road(c.road_id);
  if (!r) return std::nullopt;
  const double dir = c.from.s < 0.5 * r->length ? 1.0 : -1.0;  // away from the near end
  const double s = std::clamp(c.from.s + dir * factor, 2.0, r->length - 2.0);
  const odr::LaneIndex a = graph.find(c.road_id, graph.lane(c.from.lane).lane_id, s);
  const odr::LaneIndex b = graph.find(c.road_id, graph.lane(c.to.lane).lane_id, s);
  if (a == odr::kNoLane || b == odr::kNoLane) return std::nullopt;
  if (graph.lane(a).type != "sidewalk" || graph.lane(b).type != "sidewalk") return std::nullopt;
  return CrossPlan{c.road_id, "", {a, s}, {b, s}};
}

WalkPath make_walk_path(const odr::LaneGraph& graph, const WalkPlan& p) {
  WalkPath path;
  if (p.before && !p.before->segments.empty()) path.append(graph.sample(*p.before, kWalkSampleDs));
  if (p.cross) {
    const CrossPlan& c = *p.cross;
    const odr::WorldPose a = graph.world_pose(c.road_id, graph.lane(c.from.lane).lane_id, c.from.s);
    const odr::WorldPose b = graph.world_pose(c.road_id, graph.lane(c.to.lane).lane_id, c.to.s);
    if (path.poses.empty()) path.append({odr::Pose2{a.x, a.y, 0}});
    WalkCrossing cr;
    cr.road_id = c.road_id;
    cr.crosswalk = c.crosswalk;
    // From where the walk ended (near a) straight to b, via a.
    const double heading = std::atan2(b.y - a.y, b.x - a.x);
    path.poses.back().heading = heading;
    std::vector<odr::Pose2> line;
    line.push_back(odr::Pose2{a.x, a.y, heading});
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int n = std::max(1, static_cast<int>(std::ceil(len / kWalkSampleDs)));
    for (int i = 1; i <= n; ++i) {
      const double f = static_cast<double>(i) / n;
      line.push_back(odr::Pose2{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), heading});
    }
    const size_t first = path.poses.size();
    path.append(line);
    const size_t i0 = first > 0 ? first - 1 : 0;
    cr.start = path.arc[i0];
    cr.end = path.arc.back();
    // On the road: the part of the line outside sidewalks.
    cr.enter = cr.end;
    cr.exit = cr.start;
    for (size_t i = i0; i < path.poses.size(); ++i) {
      const auto loc = graph.locate(path.poses[i].x, path.poses[i].y, std::nullopt, 2.0);
      if (loc && loc->distance <= 0 && graph.lane(loc->lane).type == "sidewalk") continue;
      cr.enter = std::min(cr.enter, path.arc[i] - 0.5 * kWalkSampleDs);
      cr.exit = std::max(cr.exit, path.arc[i] + 0.5 * kWalkSampleDs);
    }
    if (cr.exit < cr.enter) cr.enter = cr.exit = cr.start;  // nothing to cross
    if (!c.crosswalk.empty()) {
      for (const auto& sig : graph.signals()) {
        if (!sig.signal || sig.road_id != c.road_id) continue;
        if (std::abs(sig.signal->s - c.from.s) > kSignalNear) continue;
        if (sig.pedestrian_light) cr.ped_signals.push_back(sig.signal->id);
        if (sig.traffic_light) cr.veh_signals.push_back(sig.signal->id);
      }
    }
    path.road_crossings.push_back(cr);
    if (p.after && !p.after->segments.empty()) path.append(graph.sample(*p.after, kWalkSampleDs));
  }
  return path;
}

std::optional<odr::LanePosition> nearest_sidewalk(const odr::LaneGraph& graph, double x, double y) {
  return graph.locate_if(x, y, std::nullopt, 50.0,
                         [](const odr::LaneNode& n, double) { return n.type == "sidewalk"; });
}

void append_leg(const odr::LaneGraph& graph, WalkPath& path, double ax, double ay, double bx,
                double by) {
  const double len = std::hypot(bx - ax, by - ay);
  if (len < 1e-6) return;
  const double heading = std::atan2(by - ay, bx - ax);
  if (!path.poses.empty()) path.poses.back().heading = heading;
  std::vector<odr::Pose2> line;
  line.push_back(odr::Pose2{ax, ay, heading});
  const int n = std::max(1, static_cast<int>(std::ceil(len / kWalkSampleDs)));
  for (int i = 1; i <= n; ++i) {
    const double f = static_cast<double>(i) / n;
    line.push_back(odr::Pose2{ax + f * (bx - ax), ay + f * (by - ay), heading});
  }
  const size_t first = path.poses.size();
  path.append(line);
  const size_t i0 = first > 0 ? first - 1 : 0;
  WalkCrossing cr;
  cr.start = path.arc[i0];
  cr.end = path.arc.back();
  cr.enter = cr.end;
  cr.exit = cr.start;
  for (size_t i = i0; i < path.poses.size(); ++i) {
    const auto loc = graph.locate(path.poses[i].x, path.poses[i].y, std::nullopt, 2.0);
    if (loc && loc->distance <= 0 && graph.lane(loc->lane).type == "sidewalk") continue;
    cr.enter = std::min(cr.enter, path.arc[i] - 0.5 * kWalkSampleDs);
    cr.exit = std::max(cr.exit, path.arc[i] + 0.5 * kWalkSampleDs);
  }
  if (cr.exit > cr.enter) {
    cr.enter = std::max(cr.enter, cr.start);
    cr.exit = std::min(cr.exit, cr.end);
    path.road_crossings.push_back(cr);
  }
}

bool walk_path_from(const odr::LaneGraph& graph, WalkPath& path, double x, double y, double yaw,
                    const std::optional<Spot>& dest, std::mt19937_64& rng, double* join) {
  const auto loc = nearest_sidewalk(graph, x, y);
  if (!loc) return false;
  const odr::WorldPose w = graph.world_pose(loc->road_id, loc->lane_id, loc->s);
  append_leg(graph, path, x, y, w.x, w.y);
  if (join) *join = (path.arc.empty() ? 0.0 : path.arc.back()) + 0.5;  // past the corner
  const Spot from{loc->lane, loc->s};
  if (dest) {
    const WalkPlan p = plan_walk(graph, from, *dest, nullptr);
    if (p.before) {
      const WalkPath rest = make_walk_path(graph, p);
      if (rest.poses.empty()) return true;
      const double base = path.arc.empty() ? 0.0 : path.arc.back();
      const double gap = path.poses.empty() ? 0.0
                                            : std::hypot(rest.poses[0].x - path.poses.back().x,
                                                         rest.poses[0].y - path.poses.back().y);
      const double offset = base + (gap < 1e-6 ? 0.0 : gap);
      path.append(rest.poses);
      for (WalkCrossing c : rest.road_crossings) {
        c.start += offset;
        c.end += offset;
        c.enter += offset;
        c.exit += offset;
        path.road_crossings.push_back(c);
      }
      return true;
    }
  }
  // Along the sidewalks onward, the way it faces; at each fork a choice drawn from Seed.
  const odr::LaneNode& n0 = graph.lane(loc->lane);
  const double h_s = w.heading + (n0.forward ? 0.0 : M_PI);  // the lane's +s direction
  bool with_s = std::abs(std::remainder(yaw - h_s, 2 * M_PI)) <= M_PI / 2;
  odr::LaneRoute route;
  odr::LaneIndex cur = loc->lane;
  double cs = loc->s, length = 0;
  for (int guard = 0; guard < 10000 && length < 1000.0; ++guard) {
    const odr::LaneNode& n = graph.lane(cur);
    odr::RouteSegment seg;
    seg.lane = cur;
    seg.road_id = n.road->id;
    seg.lane_id = n.lane_id;
    seg.junction = n.junction;
    seg.s_from = std::clamp(cs, n.s0, n.s1);
    seg.s_to = with_s ? n.s1 : n.s0;
    if (n.s1 > n.s0) length += std::abs(seg.s_to - seg.s_from) / (n.s1 - n.s0) * n.length;
    route.segments.push_back(seg);
    std::vector<odr::LaneEndRef> next;
    for (const odr::LaneEndRef& r : with_s ? n.at_end : n.at_start) {
      if (graph.lane(r.lane).type == "sidewalk") next.push_back(r);
    }
    if (next.empty()) break;
    const odr::LaneEndRef r = next.size() == 1 ? next[0] : next[rng() % next.size()];
    cur = r.lane;
    with_s = r.end == odr::LaneEnd::kStart;
    cs = with_s ? graph.lane(cur).s0 : graph.lane(cur).s1;
  }
  route.length = length;
  path.append(graph.sample(route, kWalkSampleDs));
  return true;
}

bool walk_through(const odr::LaneGraph& graph, WalkPath& path, double x, double y, double yaw,
                  const Points& via, const std::optional<Spot>& dest, std::mt19937_64& rng,
                  double* join) {
  path.append({odr::Pose2{x, y, yaw}});
  for (const auto& [px, py] : via)
    append_leg(graph, path, path.poses.back().x, path.poses.back().y, px, py);
  const double h = path.poses.size() > 1 ? path.poses.back().heading : yaw;
  return walk_path_from(graph, path, path.poses.back().x, path.poses.back().y, h, dest, rng, join);
}

WalkPath polyline_walk(const Points& points, double yaw) {
  std::vector<odr::Pose2> poses;
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t j = i + 1 < points.size() ? i + 1 : i;
    const double h = j != i ? std::atan2(points[j][1] - points[i][1], points[j][0] - points[i][0])
                            : (poses.empty() ? yaw : poses.back().heading);
    if (i + 1 < points.size()) {
      const double len = std::hypot(points[j][0] - points[i][0], points[j][1] - points[i][1]);
      const int n = std::max(1, static_cast<int>(std::ceil(len / kWalkSampleDs)));
      for (int k = 0; k < n; ++k) {
        const double f = static_cast<double>(k) / n;
        poses.push_back(odr::Pose2{points[i][0] + f * (points[j][0] - points[i][0]),
                                   points[i][1] + f * (points[j][1] - points[i][1]), h});
      }
    } else {
      poses.push_back(odr::Pose2{points[i][0], points[i][1], h});
    }
  }
  WalkPath t;
  t.append(poses);
  return t;
}

WalkStep step_along(const WalkPath& t, double x, double y, double yaw, double v, double dt) {
  size_t best = 0;
  double d2 = INFINITY;
  for (size_t i = 0; i < t.poses.size(); ++i) {
    const double dx = t.poses[i].x - x, dy = t.poses[i].y - y;
    if (dx * dx + dy * dy < d2) {
      d2 = dx * dx + dy * dy;
      best = i;
    }
  }
  const odr::Pose2& end = t.poses.back();
  const double ahead = t.arc[best] + 0.5;
  const odr::Pose2 target = ahead >= t.length() ? end : t.at(ahead);
  const double dx = target.x - x, dy = target.y - y;
  const double dist = std::hypot(dx, dy);
  double step = v * dt;
  if (ahead >= t.length()) step = std::min(step, dist);  // stops at its end
  if (dist <= 1e-9 || step <= 0) return {x, y, yaw, 0};
  return {x + step * dx / dist, y + step * dy / dist, std::atan2(dy, dx), step};
}

}  // namespace convoy::road_users
