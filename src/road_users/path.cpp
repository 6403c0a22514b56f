#include "road_users/path.h"

#include <algorithm>

namespace convoy::road_users {

namespace odr = convoy::opendrive;

odr::Pose2 Path::at(double a) const {
  if (poses.empty()) return {};
  if (a <= 0) return poses.front();
  if (a >= arc.back()) return poses.back();
  size_t i = std::upper_bound(arc.begin(), arc.end(), a) - arc.begin();
  const odr::Pose2& p = poses[i - 1];
  const odr::Pose2& q = poses[i];
  const double f = (a - arc[i - 1]) / std::max(arc[i] - arc[i - 1], 1e-9);
  odr::Pose2 r = p;
  r.x = p.x + f * (q.x - p.x);
  r.y = p.y + f * (q.y - p.y);
  r.heading = p.heading + f * std::remainder(q.heading - p.heading, 2 * M_PI);
  return r;
}

size_t Path::index_at(double a) const {
  return static_cast<size_t>(std::lower_bound(arc.begin(), arc.end(), a) - arc.begin());
}

Path::Proj Path::project(double x, double y, size_t lo, size_t hi, size_t hint) const {
  Proj best;
  hi = std::min(hi, poses.size());
  const auto dist2 = [&](size_t i) {
    const double dx = x - poses[i].x, dy = y - poses[i].y;
    return dx * dx + dy * dy;
  };
  // An upper bound of the nearest distance first: the hinted pose's, else every 8th pose's.
  double bound2 = INFINITY;
  if (hint >= lo && hint < hi) {
    bound2 = std::min({dist2(hint), dist2(lo), dist2(hi - 1)});
  } else {
    for (size_t i = lo; i < hi; i += 8) bound2 = std::min(bound2, dist2(i));
  }
  const double bound = std::sqrt(bound2);
  // The path from pose i to a later pose j is at least as long as the straight line between
  // them (arcs are sums of straight steps), so pose j is at least d - (arc[j] - arc[i]) from
  // (x, y): the poses within d - bound of arc[i] are farther than the nearest one and are
  // skipped. The margin keeps the result exactly that of trying every pose in order.
  for (size_t i = lo; i < hi;) {
    const double d2 = dist2(i);
    if (d2 < best.d2) {
      best.d2 = d2;
      best.index = i;
    }
    const double reach = std::sqrt(d2) - bound - 1e-6;
    if (i + 1 >= hi || reach <= arc[i + 1] - arc[i]) {
      ++i;
      continue;
    }
    const auto from = arc.begin() + static_cast<std::ptrdiff_t>(i + 1);
    const auto to = arc.begin() + static_cast<std::ptrdiff_t>(hi);
    i = static_cast<size_t>(std::lower_bound(from, to, arc[i] + reach) - arc.begin());
  }
  if (!std::isfinite(best.d2)) return best;
  const odr::Pose2& p = poses[best.index];
  const double c = std::cos(p.heading), s = std::sin(p.heading);
  const double dx = x - p.x, dy = y - p.y;
  best.arc = arc[best.index] + dx * c + dy * s;
  best.lateral = -dx * s + dy * c;
  return best;
}

void Path::append(const std::vector<odr::Pose2>& more) {
  for (const auto& p : more) {
    if (!poses.empty()) {
      const double d = std::hypot(p.x - poses.back().x, p.y - poses.back().y);
      if (d < 1e-6) continue;
      arc.push_back(arc.back() + d);
    } else {
      arc.push_back(0);
    }
    poses.push_back(p);
  }
}

namespace {

// Stop lines: each traffic light that applies to a lane of the route, where the route passes
// its s.
void add_stops(const odr::LaneGraph& graph, Path& p) {
  for (const auto& sig : graph.signals()) {
    if (!sig.traffic_light || !sig.signal) continue;
    for (const auto& seg : p.route.segments) {
      if (seg.road_id != sig.road_id) continue;
      if (std::find(sig.lanes.begin(), sig.lanes.end(), seg.lane) == sig.lanes.end()) continue;
      const double lo = std::min(seg.s_from, seg.s_to), hi = std::max(seg.s_from, seg.s_to);
      const double s = sig.signal->s;
      if (s < lo - 1e-6 || s > hi + 1e-6) continue;
      const odr::WorldPose w = graph.world_pose(seg.road_id, seg.lane_id, s);
      const auto pr = p.project(w.x, w.y);
      if (pr.d2 < 4.0) p.stops.emplace_back(pr.arc, sig.signal->id);
    }
  }
  std::sort(p.stops.begin(), p.stops.end());
}

// Junction crossings: runs of segments in one junction, from the first one's start to the
// last one's end.
void add_crossings(const odr::LaneGraph& graph, Path& p) {
  const auto& segs = p.route.segments;
  for (size_t i = 0; i < segs.size();) {
    if (segs[i].junction == "-1") {
      ++i;
      continue;
    }
    size_t j = i;
    while (j + 1 < segs.size() && segs[j + 1].junction == segs[i].junction) ++j;
    const odr::WorldPose a = graph.world_pose(segs[i].road_id, segs[i].lane_id, segs[i].s_from);
    const odr::WorldPose b = graph.world_pose(segs[j].road_id, segs[j].lane_id, segs[j].s_to);
    const auto pa = p.project(a.x, a.y), pb = p.project(b.x, b.y);
    p.crossings.push_back({segs[i].junction, std::max(0.0, pa.arc), pb.arc});
    i = j + 1;
  }
}

}  // namespace

Path make_path(const odr::LaneGraph& graph, const odr::LaneRoute& route, double ds) {
  Path p;
  p.route = route;
  p.poses = graph.sample(route, ds);
  p.arc.resize(p.poses.size());
  for (size_t i = 1; i < p.poses.size(); ++i) {
    p.arc[i] =
        p.arc[i - 1] + std::hypot(p.poses[i].x - p.poses[i - 1].x, p.poses[i].y - p.poses[i - 1].y);
  }
  add_stops(graph, p);
  add_crossings(graph, p);
  return p;
}

Path polyline_path(const Points& points, double ds, double from_x, double from_y) {
  Path path;
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    const auto [ax, ay] = points[i];
    const auto [bx, by] = points[i + 1];
    const double len = std::hypot(bx - ax, by - ay);
    if (len < 1e-9) continue;
    const double h = std::atan2(by - ay, bx - ax);
    const int n = std::max(1, static_cast<int>(std::ceil(len / ds)));
    for (int k = path.poses.empty() ? 0 : 1; k <= n; ++k) {
      odr::Pose2 p;
      p.x = ax + (bx - ax) * k / n;
      p.y = ay + (by - ay) * k / n;
      p.heading = h;
      const double a = path.poses.empty() ? 0.0
                                          : path.arc.back() + std::hypot(p.x - path.poses.back().x,
                                                                         p.y - path.poses.back().y);
      path.poses.push_back(p);
      path.arc.push_back(a);
    }
  }
  if (path.poses.empty() && !points.empty()) {  // one point (or all the same): towards it
    odr::Pose2 p;
    p.x = points[0][0];
    p.y = points[0][1];
    p.heading = std::atan2(p.y - from_y, p.x - from_x);
    path.poses = {p};
    path.arc = {0.0};
  }
  return path;
}

}  // namespace convoy::road_users
