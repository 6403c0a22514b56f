#include "traffic_pool/network.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace convoy::traffic_pool {

namespace odr = convoy::opendrive;
using road_users::Light;

odr::Pose2 PoolLane::at(double s) const {
  if (poses.size() < 2) return poses.empty() ? odr::Pose2{} : poses[0];
  s = std::clamp(s, 0.0, length);
  const size_t i = std::min(static_cast<size_t>(s / ds), poses.size() - 2);
  const odr::Pose2& a = poses[i];
  const odr::Pose2& b = poses[i + 1];
  const double seg = std::hypot(b.x - a.x, b.y - a.y);
  const double f = seg > 1e-9 ? std::clamp((s - i * ds) / seg, 0.0, 1.0) : 0.0;
  odr::Pose2 p;
  p.x = a.x + f * (b.x - a.x);
  p.y = a.y + f * (b.y - a.y);
  p.heading = a.heading + f * std::remainder(b.heading - a.heading, 2 * M_PI);
  return p;
}

Light LightCycle::state(double t, double offset_s, int group) const {
  const double half = green_s + yellow_s + all_red_s;
  double u = std::fmod(t + offset_s + (group == 1 ? half : 0.0), period());
  if (u < 0) u += period();
  if (u < green_s) return Light::kGreen;
  if (u < green_s + yellow_s) return Light::kYellow;
  return Light::kRed;
}

PoolNetwork::PoolNetwork(const odr::LaneGraph& graph, double ds) : graph_(&graph) {
  add_lanes(ds);
  link();
  find_conflicts();
  find_stop_lines();
  find_signals();
}

uint32_t PoolNetwork::pool_lane(odr::LaneIndex graph_lane) const {
  return graph_lane < by_graph_lane_.size() ? by_graph_lane_[graph_lane] : kNone;
}

Light PoolNetwork::light(uint32_t approach_lane, double t) const {
  const PoolLane& l = lanes_[approach_lane];
  if (l.approach < 0 || l.group < 0) return Light::kOff;
  const PoolJunction& j = junctions_[l.approach];
  return cycle_.state(t, j.offset_s, l.group);
}

namespace {
int restrictiveness(Light l) {
  switch (l) {
    case Light::kRed:
      return 4;
    case Light::kRedYellow:
      return 3;
    case Light::kYellow:
      return 2;
    case Light::kGreen:
      return 1;
    default:
      return 0;
  }
}
}  // namespace

Light stricter(Light a, Light b) { return restrictiveness(b) > restrictiveness(a) ? b : a; }

Light PoolNetwork::signal_light(uint32_t lane, const road_users::LightStates& states) const {
  Light out = Light::kOff;
  for (const std::string& id : lanes_[lane].signals) {
    const auto it = states.find(id);
    out = stricter(out, it == states.end() ? Light::kGreen : it->second);
  }
  return out;
}

void PoolNetwork::add_lanes(double ds) {
  by_graph_lane_.assign(graph_->lanes().size(), kNone);
  std::map<std::string, int> junction_index;
  bool first = true;
  for (const odr::LaneNode& n : graph_->lanes()) {
    if (!n.drivable() || n.length < 0.05) continue;
    PoolLane l;
    l.graph_lane = n.index;
    l.road_id = n.road->id;
    l.lane_id = n.lane_id;
    odr::LaneRoute r;
    odr::RouteSegment seg;
    seg.lane = n.index;
    seg.road_id = n.road->id;
    seg.lane_id = n.lane_id;
    seg.junction = n.junction;
    seg.s_from = n.forward ? n.s0 : n.s1;
    seg.s_to = n.forward ? n.s1 : n.s0;
    r.segments.push_back(seg);
    r.length = n.length;
    l.poses = graph_->sample(r, ds);
    l.ds = ds;
    l.length = n.length;
    if (l.poses.size() >= 2) {
      // The sampled polyline is what vehicles drive: its length is the lane's.
      l.length = ds * static_cast<double>(l.poses.size() - 2) +
                 std::hypot(l.poses.back().x - l.poses[l.poses.size() - 2].x,
                            l.poses.back().y - l.poses[l.poses.size() - 2].y);
    }
    const odr::SpeedLimit lim = graph_->speed_limit(n.index, 0.5 * (n.s0 + n.s1));
    if (lim.known && std::isfinite(lim.mps) && lim.mps > 0) l.limit = lim.mps;
    if (n.junction != "-1" && !n.junction.empty()) {
      auto [it, added] = junction_index.emplace(n.junction, static_cast<int>(junctions_.size()));
      if (added) {
        PoolJunction j;
        j.id = n.junction;
        j.lights = !graph_->junction_signals(n.junction).empty();
        j.offset_s = std::fmod(13.0 * static_cast<double>(junctions_.size()), cycle_.period());
        junctions_.push_back(j);
      }
      l.junction = it->second;
    }
    for (const odr::Pose2& p : l.poses) {
      if (first) {
        min_x = max_x = p.x;
        min_y = max_y = p.y;
        first = false;
      }
      min_x = std::min(min_x, p.x);
      max_x = std::max(max_x, p.x);
      min_y = std::min(min_y, p.y);
      max_y = std::max(max_y, p.y);
    }
    if (l.poses.size() >= 2) {
      l.u_turn =
          std::abs(std::remainder(l.poses.back().heading - l.poses[0].heading, 2 * M_PI)) > 2.6;
    }
    by_graph_lane_[n.index] = static_cast<uint32_t>(lanes_.size());
    lanes_.push_back(std::move(l));
  }
}

void PoolNetwork::link() {
  for (PoolLane& l : lanes_) {
    const odr::LaneNode& n = graph_->lane(l.graph_lane);
    for (odr::LaneIndex s : graph_->successors(l.graph_lane)) {
      const uint32_t p = pool_lane(s);
      if (p != kNone && std::find(l.next.begin(), l.next.end(), p) == l.next.end())
        l.next.push_back(p);
    }
    if (n.change_left()) l.left = pool_lane(n.left());
    if (n.change_right()) l.right = pool_lane(n.right());
    if (l.junction >= 0) l.left = l.right = kNone;
    for (uint32_t s : l.next) {
      if (l.junction < 0 && lanes_[s].junction >= 0) l.approach = lanes_[s].junction;
    }
  }
  // A junction has lights when its controllers name signals, or a traffic light stands on a
  // road leading into it (SUMO's OpenDRIVE gives signals without controllers).
  std::set<std::string> lit_roads;
  for (const odr::SignalInfo& s : graph_->signals()) {
    if (s.traffic_light) lit_roads.insert(s.road_id);
  }
  for (const PoolLane& l : lanes_) {
    if (l.approach >= 0 && lit_roads.count(l.road_id)) junctions_[l.approach].lights = true;
  }
  for (PoolLane& l : lanes_) {
    if (l.approach >= 0 && junctions_[l.approach].lights && l.poses.size() >= 2) {
      const double h = l.poses.back().heading;
      l.group = std::abs(std::cos(h)) >= std::abs(std::sin(h)) ? 0 : 1;
    }
  }
}

namespace {
bool segments_cross(const odr::Pose2& a, const odr::Pose2& b, const odr::Pose2& c,
                    const odr::Pose2& d) {
  auto cross = [](double ux, double uy, double vx, double vy) { return ux * vy - uy * vx; };
  const double d1 = cross(b.x - a.x, b.y - a.y, c.x - a.x, c.y - a.y);
  const double d2 = cross(b.x - a.x, b.y - a.y, d.x - a.x, d.y - a.y);
  const double d3 = cross(d.x - c.x, d.y - c.y, a.x - c.x, a.y - c.y);
  const double d4 = cross(d.x - c.x, d.y - c.y, b.x - c.x, b.y - c.y);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}

// Whether two lanes' centres come within `clearance` of each other (a crossing, or lanes so
// close that cars on both would touch), apart from their first metres when they leave the
// same lane.
bool lanes_conflict(const PoolLane& a, const PoolLane& b, bool same_start, double clearance) {
  const size_t skip = same_start ? static_cast<size_t>(6.0 / a.ds) : 0;
  for (size_t i = skip; i + 1 < a.poses.size(); ++i) {
    for (size_t k = same_start ? static_cast<size_t>(6.0 / b.ds) : 0; k + 1 < b.poses.size(); ++k) {
      if (segments_cross(a.poses[i], a.poses[i + 1], b.poses[k], b.poses[k + 1])) return true;
      if (std::hypot(a.poses[i].x - b.poses[k].x, a.poses[i].y - b.poses[k].y) < clearance)
        return true;
    }
  }
  return false;
}
}  // namespace

void PoolNetwork::find_conflicts() {
  std::vector<std::vector<uint32_t>> in_junction(junctions_.size());
  std::vector<uint32_t> pred(lanes_.size(), kNone);
  for (uint32_t i = 0; i < lanes_.size(); ++i) {
    if (lanes_[i].junction >= 0) in_junction[lanes_[i].junction].push_back(i);
    for (uint32_t s : lanes_[i].next) pred[s] = i;
  }
  for (const std::vector<uint32_t>& lanes : in_junction) {
    for (size_t i = 0; i < lanes.size(); ++i) {
      for (size_t k = i + 1; k < lanes.size(); ++k) {
        PoolLane& a = lanes_[lanes[i]];
        PoolLane& b = lanes_[lanes[k]];
        const bool same_start = pred[lanes[i]] == pred[lanes[k]] && pred[lanes[i]] != kNone;
        bool merge = false;
        for (uint32_t n : a.next)
          merge = merge || std::find(b.next.begin(), b.next.end(), n) != b.next.end();
        if (merge || same_start || lanes_conflict(a, b, false, 2.8)) {
          a.conflicts.push_back(lanes[k]);
          b.conflicts.push_back(lanes[i]);
        }
      }
    }
  }
}

void PoolNetwork::find_stop_lines() {
  constexpr double kReach = 15, kHalfCrosswalk = 2.0, kMargin = 0.5;
  for (const odr::Crosswalk& cw : graph_->crosswalks()) {
    for (odr::LaneIndex gl : cw.lanes) {
      const uint32_t p = pool_lane(gl);
      if (p == kNone || lanes_[p].approach < 0) continue;
      const odr::LaneNode& n = graph_->lane(gl);
      const double to_end = n.forward ? n.s1 - cw.s : cw.s - n.s0;
      if (to_end < 0 || to_end > kReach) continue;
      lanes_[p].stop_back = std::max(lanes_[p].stop_back, to_end + kHalfCrosswalk + kMargin);
    }
  }
}

// The traffic lights of each lane (PoolLane::signals): those the map applies to it
// (SignalInfo::lanes, as road_users::red_for reads them); an approach's within kSignalReach m
// of its end, on it or on the lanes before it on its road (a road of several sections).
void PoolNetwork::find_signals() {
  std::vector<std::vector<const odr::SignalInfo*>> on(graph_->lanes().size());
  for (const odr::SignalInfo& s : graph_->signals()) {
    if (!s.traffic_light || !s.signal) continue;
    for (odr::LaneIndex l : s.lanes) on[l].push_back(&s);
  }
  const auto add = [](PoolLane& l, const odr::SignalInfo* s) {
    if (std::find(l.signals.begin(), l.signals.end(), s->signal->id) == l.signals.end())
      l.signals.push_back(s->signal->id);
  };
  for (PoolLane& l : lanes_) {
    if (l.junction >= 0) {
      for (const odr::SignalInfo* s : on[l.graph_lane]) add(l, s);
      continue;
    }
    if (l.approach < 0 || l.poses.empty()) continue;
    const odr::Pose2& end = l.poses.back();
    odr::LaneIndex g = l.graph_lane;
    for (int back = 0; back < 4 && g != odr::kNoLane; ++back) {
      for (const odr::SignalInfo* s : on[g]) {
        if (std::hypot(s->pose.x - end.x, s->pose.y - end.y) <= kSignalReach) add(l, s);
      }
      const std::vector<odr::LaneIndex> before = graph_->predecessors(g);
      g = before.size() == 1 && graph_->lane(before[0]).road->id == l.road_id ? before[0]
                                                                              : odr::kNoLane;
    }
  }
}

}  // namespace convoy::traffic_pool
