#include "opendrive/lane_graph.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <queue>
#include <stdexcept>
#include <tuple>

#include "opendrive/sampling.h"

namespace convoy::opendrive {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double wrap(double a) { return std::remainder(a, 2 * std::numbers::pi); }

// Centre t of a lane (within a known section) at s, its slope, and the lane's heading there.
struct LaneCentre {
  double t = 0;
  double slope = 0;
  double inner = 0, outer = 0;
};

LaneCentre centre(const Road& road, size_t section, double s, int lane_id) {
  const LaneBorders b = road.lane_borders(section, s, lane_id);
  return {0.5 * (b.inner + b.outer), 0.5 * (b.inner_slope + b.outer_slope), b.inner, b.outer};
}

// Pose at lateral offset t (slope dt/ds) from the reference line, heading along s.
Pose2 offset_pose(const Road& road, double s, double t, double slope) {
  Pose2 p = road.offset_point(s, t);
  const double stretch = 1 - p.curvature * t;
  p.heading += std::atan2(slope, stretch);
  p.curvature = std::abs(stretch) > 1e-9 ? p.curvature / stretch : 0.0;
  return p;
}

// Road marks that forbid crossing them.
bool crossable(const std::string& type) {
  return !(type == "solid" || type == "solid solid" || type == "curb" || type == "grass" ||
           type == "edge");
}

// The road mark of `lane` at s (its outer border), "none" without one.
std::string mark_at(const Lane& lane, double s) {
  std::string type = "none";
  for (const RoadMark& m : lane.road_marks) {
    if (m.start <= s + 1e-9) type = m.type;
  }
  return type;
}

}  // namespace

LaneIndex LaneNode::left() const {
  const bool inner_is_left = forward == (lane_id < 0);
  return inner_is_left ? inner : outer;
}
LaneIndex LaneNode::right() const {
  const bool inner_is_left = forward == (lane_id < 0);
  return inner_is_left ? outer : inner;
}
bool LaneNode::change_left() const {
  const bool inner_is_left = forward == (lane_id < 0);
  return inner_is_left ? change_to_inner : change_to_outer;
}
bool LaneNode::change_right() const {
  const bool inner_is_left = forward == (lane_id < 0);
  return inner_is_left ? change_to_outer : change_to_inner;
}

LaneGraph::LaneGraph(const Network& network) : net_(&network) {
  for (size_t i = 0; i < network.roads.size(); ++i) road_by_id_[network.roads[i].id] = i;
  add_lanes();
  link_sections();
  link_roads();
  link_junctions();
  index_geometry();
  collect_objects();
}

void LaneGraph::fail(const std::string& what) const {
  throw std::runtime_error(net_->source + ": " + what);
}

void LaneGraph::add_lanes() {
  roads_.resize(net_->roads.size());
  for (size_t r = 0; r < net_->roads.size(); ++r) {
    const Road& road = net_->roads[r];
    RoadIndex& ri = roads_[r];
    for (size_t k = 0; k < road.sections.size(); ++k) {
      const LaneSection& sec = road.sections[k];
      ri.section_min_id.push_back(sec.min_lane_id());
      ri.section_lanes.emplace_back(sec.lanes.size(), kNoLane);
      SamplingOptions coarse;
      coarse.max_straight_segment = 20;
      coarse.max_varying_segment = 5;
      coarse.max_curve_segment = 2;
      coarse.chord_tolerance = 0.01;
      const std::vector<double> stations = sec.s_end > sec.s
                                               ? road_stations(road, sec.s, sec.s_end, coarse)
                                               : std::vector<double>{sec.s};
      for (const Lane& lane : sec.lanes) {
        if (lane.id == 0) continue;
        LaneNode n;
        n.index = static_cast<LaneIndex>(lanes_.size());
        n.road = &road;
        n.road_index = r;
        n.section = k;
        n.lane_id = lane.id;
        n.type = lane.type;
        n.s0 = sec.s;
        n.s1 = sec.s_end;
        n.forward = road.rule == "LHT" ? lane.id > 0 : lane.id < 0;
        n.junction = road.junction;
        double len = 0;
        Pose2 last;
        for (size_t i = 0; i < stations.size(); ++i) {
          const LaneCentre c = centre(road, k, stations[i], lane.id);
          const Pose2 p = road.offset_point(stations[i], c.t);
          if (i > 0) len += std::hypot(p.x - last.x, p.y - last.y);
          last = p;
        }
        n.length = len;
        ri.section_lanes[k][lane.id - sec.min_lane_id()] = n.index;
        lanes_.push_back(std::move(n));
      }
      // Neighbours on the same side and whether the mark between them may be crossed.
      const double mid = 0.5 * (sec.s + sec.s_end);
      for (const Lane& lane : sec.lanes) {
        if (lane.id == 0) continue;
        LaneNode& n = lanes_[lane_in_section(r, k, lane.id)];
        const int step = lane.id > 0 ? 1 : -1;
        const int inner_id = lane.id - step, outer_id = lane.id + step;
        if (inner_id != 0) {
          n.inner = lane_in_section(r, k, inner_id);
          n.change_to_inner = crossable(mark_at(*sec.find_lane(inner_id), mid));
        }
        if (const Lane* o = sec.find_lane(outer_id)) {
          n.outer = lane_in_section(r, k, outer_id);
          n.change_to_outer = crossable(mark_at(lane, mid));
          (void)o;
        }
      }
    }
  }
}

LaneIndex LaneGraph::lane_in_section(size_t road, size_t section, int lane_id) const {
  const RoadIndex& ri = roads_[road];
  if (section >= ri.section_lanes.size()) return kNoLane;
  const int i = lane_id - ri.section_min_id[section];
  if (lane_id == 0 || i < 0 || i >= static_cast<int>(ri.section_lanes[section].size())) {
    return kNoLane;
  }
  return ri.section_lanes[section][i];
}

void LaneGraph::join(LaneEndRef a, LaneEndRef b) {
  if (a.lane == kNoLane || b.lane == kNoLane) return;
  auto add = [&](LaneEndRef from, LaneEndRef to) {
    auto& list =
        from.end == LaneEnd::kStart ? lanes_[from.lane].at_start : lanes_[from.lane].at_end;
    if (std::find(list.begin(), list.end(), to) == list.end()) list.push_back(to);
  };
  add(a, b);
  add(b, a);
}

void LaneGraph::link_sections() {
  for (size_t r = 0; r < net_->roads.size(); ++r) {
    const Road& road = net_->roads[r];
    for (size_t k = 0; k + 1 < road.sections.size(); ++k) {
      for (const Lane& lane : road.sections[k].lanes) {
        if (lane.id == 0) continue;
        const int next = lane.successor.value_or(lane.id);
        join({lane_in_section(r, k, lane.id), LaneEnd::kEnd},
             {lane_in_section(r, k + 1, next), LaneEnd::kStart});
      }
      for (const Lane& lane : road.sections[k + 1].lanes) {
        if (lane.id == 0 || !lane.predecessor) continue;
        join({lane_in_section(r, k, *lane.predecessor), LaneEnd::kEnd},
             {lane_in_section(r, k + 1, lane.id), LaneEnd::kStart});
      }
    }
  }
}

void LaneGraph::link_roads() {
  for (size_t r = 0; r < net_->roads.size(); ++r) {
    const Road& road = net_->roads[r];
    for (const bool successor : {false, true}) {
      const RoadLink& link = successor ? road.successor : road.predecessor;
      const std::string where = "road " + road.id + (successor ? " successor" : " predecessor");
      if (link.element_type == "junction") {
        if (!net_->find_junction(link.element_id)) {
          fail(where + ": junction '" + link.element_id + "' does not exist");
        }
        continue;
      }
      if (link.element_type != "road") continue;
      auto it = road_by_id_.find(link.element_id);
      if (it == road_by_id_.end()) fail(where + ": road '" + link.element_id + "' does not exist");
      const size_t q = it->second;
      const Road& other = net_->roads[q];
      // Without a contact point, a successor is entered at its start, a predecessor left at
      // its end.
      const bool at_start = link.contact_point.empty() ? successor : link.contact_point == "start";
      const size_t k = successor ? road.sections.size() - 1 : 0;
      const size_t ko = at_start ? 0 : other.sections.size() - 1;
      const LaneEnd here = successor ? LaneEnd::kEnd : LaneEnd::kStart;
      const LaneEnd there = at_start ? LaneEnd::kStart : LaneEnd::kEnd;
      // Lanes keep their side when an end meets a start, and swap it when like ends meet.
      const bool flip = (here == LaneEnd::kEnd) == (there == LaneEnd::kEnd);
      for (const Lane& lane : road.sections[k].lanes) {
        if (lane.id == 0) continue;
        const std::optional<int>& given = successor ? lane.successor : lane.predecessor;
        const int id = given.value_or(flip ? -lane.id : lane.id);
        join({lane_in_section(r, k, lane.id), here}, {lane_in_section(q, ko, id), there});
      }
    }
  }
}

void LaneGraph::link_junctions() {
  for (const Junction& j : net_->junctions) {
    for (const JunctionConnection& c : j.connections) {
      const std::string where = "junction " + j.id + " connection " + c.id;
      auto in = road_by_id_.find(c.incoming_road);
      if (in == road_by_id_.end()) {
        fail(where + ": incomingRoad '" + c.incoming_road + "' does not exist");
      }
      auto via = road_by_id_.find(c.connecting_road);
      if (via == road_by_id_.end()) {
        fail(where + ": connectingRoad '" + c.connecting_road + "' does not exist");
      }
      const Road& incoming = net_->roads[in->second];
      const Road& connecting = net_->roads[via->second];
      // Which end of the incoming road touches the junction.
      bool incoming_end;
      auto names = [&](const RoadLink& l) {
        return (l.element_type == "junction" && l.element_id == j.id) ||
               (l.element_type == "road" && l.element_id == connecting.id);
      };
      if (names(incoming.successor) && !names(incoming.predecessor)) {
        incoming_end = true;
      } else if (names(incoming.predecessor) && !names(incoming.successor)) {
        incoming_end = false;
      } else {  // both or neither: the end nearer the connecting road's contact point
        const Pose2 p = connecting.reference(c.contact_point == "start" ? 0 : connecting.length);
        const Pose2 a = incoming.reference(0), b = incoming.reference(incoming.length);
        incoming_end = std::hypot(b.x - p.x, b.y - p.y) < std::hypot(a.x - p.x, a.y - p.y);
      }
      const size_t ki = incoming_end ? incoming.sections.size() - 1 : 0;
      const bool via_start = c.contact_point == "start";
      const size_t kc = via_start ? 0 : connecting.sections.size() - 1;
      const LaneEnd ei = incoming_end ? LaneEnd::kEnd : LaneEnd::kStart;
      const LaneEnd ec = via_start ? LaneEnd::kStart : LaneEnd::kEnd;
      auto link = [&](int from, int to) {
        const LaneIndex a = lane_in_section(in->second, ki, from);
        const LaneIndex b = lane_in_section(via->second, kc, to);
        if (a == kNoLane || b == kNoLane) {
          warnings_.push_back(net_->source + ": " + where + ": laneLink " + std::to_string(from) +
                              " -> " + std::to_string(to) + ": road " +
                              (a == kNoLane ? incoming.id : connecting.id) + " has no lane " +
                              std::to_string(a == kNoLane ? from : to) + " there");
          return;
        }
        join({a, ei}, {b, ec});
      };
      if (!c.lane_links.empty()) {
        for (const auto& [from, to] : c.lane_links) link(from, to);
      } else {  // the connecting road's own lane links towards the incoming road
        for (const Lane& lane : connecting.sections[kc].lanes) {
          const std::optional<int>& back = via_start ? lane.predecessor : lane.successor;
          if (lane.id != 0 && back) link(*back, lane.id);
        }
      }
    }
  }
}

void LaneGraph::index_geometry() {
  for (size_t r = 0; r < net_->roads.size(); ++r) {
    const Road& road = net_->roads[r];
    RoadIndex& ri = roads_[r];
    SamplingOptions coarse;
    coarse.max_straight_segment = 10;
    coarse.max_varying_segment = 5;
    coarse.max_curve_segment = 2;
    coarse.chord_tolerance = 0.02;
    ri.stations = road_stations(road, 0, road.length, coarse);
    ri.min_x = ri.min_y = kInf;
    ri.max_x = ri.max_y = -kInf;
    for (double s : ri.stations) {
      const Pose2 p = road.reference(s);
      ri.points.push_back({p.x, p.y});
      const size_t k = road.section_index(s);
      const LaneSection& sec = road.sections[k];
      double reach = std::abs(road.lane_offset(s));
      for (int id : {sec.min_lane_id(), sec.max_lane_id()}) {
        if (id != 0) reach = std::max(reach, std::abs(road.lane_borders(k, s, id).outer));
      }
      ri.min_x = std::min(ri.min_x, p.x - reach);
      ri.max_x = std::max(ri.max_x, p.x + reach);
      ri.min_y = std::min(ri.min_y, p.y - reach);
      ri.max_y = std::max(ri.max_y, p.y + reach);
    }
  }
}

void LaneGraph::collect_objects() {
  std::map<std::string, std::vector<std::string>> controllers_of;  // signal id -> controllers
  for (const Controller& c : net_->controllers) {
    for (const std::string& sid : c.signal_ids) controllers_of[sid].push_back(c.id);
  }
  std::map<std::string, std::string> junction_of;  // controller id -> junction
  for (const Junction& j : net_->junctions) {
    for (const std::string& cid : j.controllers) junction_of.emplace(cid, j.id);
  }
  for (size_t r = 0; r < net_->roads.size(); ++r) {
    const Road& road = net_->roads[r];
    for (const RoadObject& o : road.objects) {
      if (o.type != "crosswalk") continue;
      Crosswalk cw;
      cw.road_id = road.id;
      cw.id = o.id;
      cw.s = o.s;
      cw.t = o.t;
      const Pose2 origin = road.offset_point(o.s, o.t);
      const double h = origin.heading + o.hdg;
      auto local = [&](double u, double v) {
        return std::array<double, 2>{origin.x + u * std::cos(h) - v * std::sin(h),
                                     origin.y + u * std::sin(h) + v * std::cos(h)};
      };
      for (const OutlineCorner& c : o.outline) {
        if (c.road) {
          const Pose2 p = road.offset_point(c.a, c.b);
          cw.polygon.push_back({p.x, p.y});
        } else {
          cw.polygon.push_back(local(c.a, c.b));
        }
      }
      if (cw.polygon.empty()) {
        const double l = 0.5 * o.length, w = 0.5 * o.width;
        cw.polygon = {local(-l, -w), local(l, -w), local(l, w), local(-l, w)};
      }
      // Lanes it covers: those of the section at s whose t range meets the polygon's.
      const Pose2 ref = road.reference(o.s);
      double t0 = kInf, t1 = -kInf;
      for (const auto& p : cw.polygon) {
        const double t =
            -(p[0] - ref.x) * std::sin(ref.heading) + (p[1] - ref.y) * std::cos(ref.heading);
        t0 = std::min(t0, t);
        t1 = std::max(t1, t);
      }
      const size_t k = road.section_index(o.s);
      std::array<double, 2> gap{kInf, kInf};
      for (const Lane& lane : road.sections[k].lanes) {
        if (lane.id == 0) continue;
        const LaneBorders b = road.lane_borders(k, o.s, lane.id);
        const double lo = std::min(b.inner, b.outer), hi = std::max(b.inner, b.outer);
        if (hi > t0 + 1e-6 && lo < t1 - 1e-6) cw.lanes.push_back(lane_in_section(r, k, lane.id));
        if (lane.type != "sidewalk" || hi - lo <= 1e-9) continue;
        const double below = t0 - hi, above = lo - t1;  // gaps to the crosswalk's ends
        if (below >= -1e-6 && below <= 3 && (cw.ends[0] == kNoLane || below < gap[0])) {
          cw.ends[0] = lane_in_section(r, k, lane.id);
          gap[0] = below;
        }
        if (above >= -1e-6 && above <= 3 && (cw.ends[1] == kNoLane || above < gap[1])) {
          cw.ends[1] = lane_in_section(r, k, lane.id);
          gap[1] = above;
        }
      }
      crosswalks_.push_back(std::move(cw));
    }
    for (const Signal& g : road.signals) {
      SignalInfo info;
      info.signal = &g;
      info.road_id = road.id;
      const Pose2 p = road.offset_point(g.s, g.t);
      info.pose = {p.x, p.y, road.elevation(g.s) + g.z_offset,
                   wrap(p.heading + g.h_offset + (g.orientation == "-" ? std::numbers::pi : 0))};
      info.traffic_light = g.dynamic && g.type == "1000001";
      info.pedestrian_light = g.dynamic && g.type == "1000002";
      const size_t k = road.section_index(g.s);
      for (const Lane& lane : road.sections[k].lanes) {
        if (lane.id == 0) continue;
        const LaneNode& n = lanes_[lane_in_section(r, k, lane.id)];
        if (info.pedestrian_light ? n.type != "sidewalk" : !n.drivable()) continue;
        if (!info.pedestrian_light && g.orientation == "+" && !n.forward) continue;
        if (!info.pedestrian_light && g.orientation == "-" && n.forward) continue;
        bool valid = g.validity.empty();
        for (const auto& [a, b] : g.validity) {
          valid = valid || (lane.id >= std::min(a, b) && lane.id <= std::max(a, b));
        }
        if (valid) info.lanes.push_back(n.index);
      }
      if (auto it = controllers_of.find(g.id); it != controllers_of.end()) {
        info.controllers = it->second;
        for (const std::string& cid : it->second) {
          if (auto jt = junction_of.find(cid); jt != junction_of.end()) {
            info.junction = jt->second;
            break;
          }
        }
      }
      signals_.push_back(std::move(info));
    }
  }
}

LaneIndex LaneGraph::find(const std::string& road_id, int lane_id, double s) const {
  auto it = road_by_id_.find(road_id);
  if (it == road_by_id_.end()) return kNoLane;
  const Road& road = net_->roads[it->second];
  return lane_in_section(it->second, road.section_index(std::clamp(s, 0.0, road.length)), lane_id);
}

LaneIndex LaneGraph::require(const std::string& road_id, int lane_id, double s) const {
  auto it = road_by_id_.find(road_id);
  if (it == road_by_id_.end()) fail("no road with id '" + road_id + "'");
  const LaneIndex i = find(road_id, lane_id, s);
  if (i == kNoLane) {
    const Road& road = net_->roads[it->second];
    const LaneSection& sec = road.sections[road.section_index(std::clamp(s, 0.0, road.length))];
    char at[32];
    std::snprintf(at, sizeof at, "%.3f", std::clamp(s, 0.0, road.length));
    fail("road " + road_id + " has no lane " + std::to_string(lane_id) + " at s=" + at +
         " (lanes " + std::to_string(sec.min_lane_id()) + ".." + std::to_string(sec.max_lane_id()) +
         ", 0 is the centre)");
  }
  return i;
}

// The lanes with this id over all sections of a road, in s order; throws without any.
static std::vector<LaneIndex> lanes_with_id(const LaneGraph& g, const Road& road, int lane_id) {
  std::vector<LaneIndex> out;
  for (const LaneSection& sec : road.sections) {
    const LaneIndex i = g.find(road.id, lane_id, sec.s + 0.5 * (sec.s_end - sec.s));
    if (i != kNoLane && (out.empty() || out.back() != i)) out.push_back(i);
  }
  return out;
}

LaneIndex LaneGraph::entry_lane(const std::string& road_id, int lane_id) const {
  auto it = road_by_id_.find(road_id);
  if (it == road_by_id_.end()) fail("no road with id '" + road_id + "'");
  const std::vector<LaneIndex> all = lanes_with_id(*this, net_->roads[it->second], lane_id);
  if (all.empty()) require(road_id, lane_id, 0);  // throws, naming the lanes there are
  if (all.empty()) fail("road " + road_id + " has no lane " + std::to_string(lane_id));
  return lanes_[all.front()].forward ? all.front() : all.back();
}

LaneIndex LaneGraph::exit_lane(const std::string& road_id, int lane_id) const {
  auto it = road_by_id_.find(road_id);
  if (it == road_by_id_.end()) fail("no road with id '" + road_id + "'");
  const std::vector<LaneIndex> all = lanes_with_id(*this, net_->roads[it->second], lane_id);
  if (all.empty()) require(road_id, lane_id, 0);
  if (all.empty()) fail("road " + road_id + " has no lane " + std::to_string(lane_id));
  return lanes_[all.front()].forward ? all.back() : all.front();
}

std::vector<LaneIndex> LaneGraph::successors(LaneIndex lane) const {
  const LaneNode& n = lanes_.at(lane);
  std::vector<LaneIndex> out;
  for (const LaneEndRef& r : n.forward ? n.at_end : n.at_start) {
    // Entered at its start = travelled with s, which must be its driving direction.
    if ((r.end == LaneEnd::kStart) == lanes_[r.lane].forward) out.push_back(r.lane);
  }
  return out;
}

std::vector<LaneIndex> LaneGraph::predecessors(LaneIndex lane) const {
  const LaneNode& n = lanes_.at(lane);
  std::vector<LaneIndex> out;
  for (const LaneEndRef& r : n.forward ? n.at_start : n.at_end) {
    if ((r.end == LaneEnd::kEnd) == lanes_[r.lane].forward) out.push_back(r.lane);
  }
  return out;
}

std::optional<LaneRoute> LaneGraph::route(LaneIndex from, double s_from, LaneIndex to, double s_to,
                                          const RouteOptions& options) const {
  if (from >= lanes_.size() || to >= lanes_.size()) fail("route: lane index out of range");
  // States: lane * 2 + (0 with s, 1 against s). dist = cost to the lane's entry in that
  // direction (for the start state: minus the progress already made).
  const size_t n_states = lanes_.size() * 2;
  auto allowed = [&](LaneIndex l, bool with_s) {
    const LaneNode& n = lanes_[l];
    return options.lane_types.count(n.type) > 0 && (options.both_directions || n.forward == with_s);
  };
  auto fraction = [&](LaneIndex l, bool with_s, double s) {
    const LaneNode& n = lanes_[l];
    if (n.s1 - n.s0 <= 0) return 0.0;
    const double f = std::clamp((s - n.s0) / (n.s1 - n.s0), 0.0, 1.0);
    return with_s ? f : 1 - f;
  };
  struct Parent {
    size_t state = SIZE_MAX;
    bool change = false;
  };
  std::vector<double> dist(n_states, kInf);
  std::vector<Parent> parent(n_states);
  std::vector<char> at_start_pos(n_states, 0), done(n_states, 0);
  using Item = std::pair<double, size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  double best = kInf;
  Parent best_parent;  // the state before the target, or none when from == to directly
  bool best_direct = false;
  size_t target_state = SIZE_MAX;
  std::vector<bool> dirs = options.both_directions ? std::vector<bool>{true, false}
                                                   : std::vector<bool>{lanes_[from].forward};
  for (bool with_s : dirs) {
    if (!allowed(from, with_s)) continue;
    const size_t st = from * 2 + (with_s ? 0 : 1);
    const double f_from = fraction(from, with_s, s_from);
    dist[st] = -f_from * lanes_[from].length;
    at_start_pos[st] = 1;
    queue.push({dist[st], st});
    if (from == to && allowed(to, with_s)) {
      const double f_to = fraction(to, with_s, s_to);
      if (f_to >= f_from - 1e-12) {
        const double c = (f_to - f_from) * lanes_[from].length;
        if (c < best) {
          best = c;
          best_direct = true;
          target_state = st;
        }
      }
    }
  }
  if (queue.empty()) return std::nullopt;
  auto reach_target = [&](size_t u, size_t v, bool change, double cost_at_entry) {
    const bool with_s = v % 2 == 0;
    const double f_to = fraction(to, with_s, s_to);
    if (change && at_start_pos[u]) {
      if (f_to < fraction(from, with_s, s_from) - 1e-12) return;
    }
    const double c = cost_at_entry + f_to * lanes_[to].length;
    if (c < best) {
      best = c;
      best_parent = {u, change};
      best_direct = false;
      target_state = v;
    }
  };
  while (!queue.empty()) {
    const double du = queue.top().first;
    const size_t u = queue.top().second;
    queue.pop();
    if (done[u] || du > dist[u]) continue;
    if (du >= best) break;
    done[u] = 1;
    const LaneIndex l = static_cast<LaneIndex>(u / 2);
    const bool with_s = u % 2 == 0;
    const LaneNode& n = lanes_[l];
    auto relax = [&](size_t v, double dv, bool change) {
      if (static_cast<LaneIndex>(v / 2) == to) reach_target(u, v, change, dv);
      if (dv < dist[v]) {
        dist[v] = dv;
        parent[v] = {u, change};
        at_start_pos[v] = change ? at_start_pos[u] : 0;
        queue.push({dv, v});
      }
    };
    // Along the lane into what follows its exit end.
    for (const LaneEndRef& r : with_s ? n.at_end : n.at_start) {
      const bool next_with_s = r.end == LaneEnd::kStart;
      if (!allowed(r.lane, next_with_s)) continue;
      relax(r.lane * 2 + (next_with_s ? 0 : 1), du + n.length, false);
    }
    if (!options.lane_changes) continue;
    for (const bool inner : {true, false}) {
      const LaneIndex m = inner ? n.inner : n.outer;
      if (m == kNoLane || !allowed(m, with_s)) continue;
      if (options.respect_road_marks && !(inner ? n.change_to_inner : n.change_to_outer)) continue;
      relax(m * 2 + (with_s ? 0 : 1), du + options.lane_change_cost, true);
    }
  }
  if (target_state == SIZE_MAX) return std::nullopt;

  // The states from start to target, and how each was entered.
  struct Step {
    size_t state;
    bool change;
  };
  std::vector<Step> steps;
  if (best_direct) {
    steps.push_back({target_state, false});
  } else {
    steps.push_back({target_state, best_parent.change});
    for (size_t st = best_parent.state; st != SIZE_MAX; st = parent[st].state) {
      steps.push_back({st, parent[st].change});
    }
    std::reverse(steps.begin(), steps.end());
  }
  steps.front().change = false;

  LaneRoute out;
  out.cost = best;
  size_t i = 0;
  while (i < steps.size()) {
    size_t j = i + 1;
    while (j < steps.size() && steps[j].change) ++j;
    // Run [i, j): one section crossed with j - i - 1 lane changes.
    const bool with_s = steps[i].state % 2 == 0;
    const LaneNode& first = lanes_[steps[i].state / 2];
    double a = i == 0 ? s_from : (with_s ? first.s0 : first.s1);
    double b = j == steps.size() ? s_to : (with_s ? first.s1 : first.s0);
    if (i == 0) a = std::clamp(a, first.s0, first.s1);
    if (j == steps.size()) b = std::clamp(b, first.s0, first.s1);
    const size_t count = j - i;
    for (size_t k = i; k < j; ++k) {
      const LaneNode& n = lanes_[steps[k].state / 2];
      RouteSegment seg;
      seg.lane = n.index;
      seg.road_id = n.road->id;
      seg.lane_id = n.lane_id;
      seg.junction = n.junction;
      seg.s_from = a + (b - a) * static_cast<double>(k - i) / static_cast<double>(count);
      seg.s_to = a + (b - a) * static_cast<double>(k - i + 1) / static_cast<double>(count);
      seg.lane_change = k > i;
      if (seg.lane_change) {
        const LaneNode& prev = lanes_[steps[k - 1].state / 2];
        // Left of the direction of travel is +t with s, -t against it.
        const bool plus_t = (n.lane_id > prev.lane_id);
        seg.change_direction = plus_t == with_s ? 1 : -1;
        ++out.lane_changes;
      }
      if (n.s1 > n.s0) out.length += std::abs(seg.s_to - seg.s_from) / (n.s1 - n.s0) * n.length;
      if (n.junction != "-1" && (out.junctions.empty() || out.junctions.back() != n.junction)) {
        out.junctions.push_back(n.junction);
      }
      out.segments.push_back(std::move(seg));
    }
    i = j;
  }
  return out;
}

std::optional<LaneRoute> LaneGraph::route(const std::string& from_road, int from_lane,
                                          const std::string& to_road, int to_lane,
                                          const RouteOptions& options) const {
  const LaneIndex a = entry_lane(from_road, from_lane);
  const LaneIndex b = exit_lane(to_road, to_lane);
  const LaneNode& na = lanes_[a];
  const LaneNode& nb = lanes_[b];
  return route(a, na.forward ? na.s0 : na.s1, b, nb.forward ? nb.s1 : nb.s0, options);
}

std::vector<Pose2> LaneGraph::sample(const LaneRoute& route, double ds) const {
  if (!(ds > 0)) fail("route sampling step must be > 0");
  const auto& segs = route.segments;
  if (segs.empty()) return {};
  // Lateral t of segment i at s, blending across lane changes at both of its ends.
  auto blend_half = [&](size_t i) {  // half-length of the blend at the start of segment i
    const double la = std::abs(segs[i - 1].s_to - segs[i - 1].s_from);
    const double lb = std::abs(segs[i].s_to - segs[i].s_from);
    return std::min({15.0, 0.5 * la, 0.5 * lb});
  };
  auto smooth = [](double w) { return w * w * (3 - 2 * w); };
  auto point = [&](size_t i, double s) {
    const LaneNode& n = lanes_[segs[i].lane];
    const Road& road = *n.road;
    double t = centre(road, n.section, s, n.lane_id).t;
    const double along_from = std::abs(s - segs[i].s_from);
    const double along_to = std::abs(segs[i].s_to - s);
    if (segs[i].lane_change) {
      const double h = blend_half(i);
      if (h > 0 && along_from < h) {
        const double tp = centre(road, n.section, s, segs[i - 1].lane_id).t;
        t = tp + (t - tp) * smooth(0.5 + 0.5 * along_from / h);
      }
    }
    if (i + 1 < segs.size() && segs[i + 1].lane_change) {
      const double h = blend_half(i + 1);
      if (h > 0 && along_to < h) {
        const double tn = centre(road, n.section, s, segs[i + 1].lane_id).t;
        t = t + (tn - t) * smooth(0.5 - 0.5 * along_to / h);
      }
    }
    const Pose2 p = road.offset_point(s, t);
    return std::array<double, 2>{p.x, p.y};
  };
  SamplingOptions fine;
  fine.max_curve_segment = 0.25;
  fine.max_straight_segment = 1.0;
  fine.max_varying_segment = 0.25;
  struct Knot {
    size_t seg;
    double s;
    double ell;
    std::array<double, 2> p;
  };
  std::vector<Knot> knots;
  double ell = 0;
  for (size_t i = 0; i < segs.size(); ++i) {
    const RouteSegment& g = segs[i];
    const Road& road = *lanes_[g.lane].road;
    const double lo = std::min(g.s_from, g.s_to), hi = std::max(g.s_from, g.s_to);
    std::vector<double> st = hi > lo ? road_stations(road, lo, hi, fine) : std::vector<double>{lo};
    if (g.s_from > g.s_to) std::reverse(st.begin(), st.end());
    for (double s : st) {
      const auto p = point(i, s);
      if (!knots.empty()) ell += std::hypot(p[0] - knots.back().p[0], p[1] - knots.back().p[1]);
      knots.push_back({i, s, ell, p});
    }
  }
  if (ell / ds > kMaxSamples) fail("route too long to sample every " + std::to_string(ds) + " m");
  std::vector<double> targets;
  for (double t = 0; t < ell - 1e-6; t += ds) targets.push_back(t);
  targets.push_back(ell);
  std::vector<Pose2> out;
  size_t j = 0;
  for (double t : targets) {
    while (j + 2 < knots.size() && knots[j + 1].ell <= t) ++j;
    const Knot& a = knots[j];
    const Knot& b = knots[std::min(j + 1, knots.size() - 1)];
    const double w = b.ell > a.ell ? std::clamp((t - a.ell) / (b.ell - a.ell), 0.0, 1.0) : 0.0;
    Pose2 p;
    p.x = a.p[0] + w * (b.p[0] - a.p[0]);
    p.y = a.p[1] + w * (b.p[1] - a.p[1]);
    // Heading of the travel direction from a short chord at the point.
    const Knot& k = w < 0.5 ? a : b;
    const RouteSegment& g = segs[k.seg];
    const double dir = g.s_to >= g.s_from ? 1 : -1;
    const double lo = std::min(g.s_from, g.s_to), hi = std::max(g.s_from, g.s_to);
    const double s_here = a.seg == b.seg ? a.s + w * (b.s - a.s) : k.s;
    const double e = 0.05;
    const auto p0 = point(k.seg, std::clamp(s_here - dir * e, lo, hi));
    const auto p1 = point(k.seg, std::clamp(s_here + dir * e, lo, hi));
    if (std::hypot(p1[0] - p0[0], p1[1] - p0[1]) > 1e-9) {
      p.heading = std::atan2(p1[1] - p0[1], p1[0] - p0[0]);
    } else if (!out.empty()) {
      p.heading = out.back().heading;
    }
    out.push_back(p);
  }
  for (size_t i = 1; i + 1 < out.size(); ++i) {
    const double dl = std::hypot(out[i + 1].x - out[i - 1].x, out[i + 1].y - out[i - 1].y);
    if (dl > 1e-9) out[i].curvature = wrap(out[i + 1].heading - out[i - 1].heading) / dl;
  }
  return out;
}

WorldPose LaneGraph::world_pose(const std::string& road_id, int lane_id, double s, double t) const {
  const LaneIndex i = require(road_id, lane_id, s);
  const LaneNode& n = lanes_[i];
  const Road& road = *n.road;
  const LaneCentre c = centre(road, n.section, s, lane_id);
  const Pose2 p = offset_pose(road, s, c.t + t, c.slope);
  return {p.x, p.y, road.surface_z(s, c.t + t),
          wrap(p.heading + (n.forward ? 0 : std::numbers::pi))};
}

std::optional<LanePosition> LaneGraph::locate(double x, double y, std::optional<double> heading,
                                              double max_distance) const {
  return locate_if(x, y, heading, max_distance, {});
}

std::optional<LanePosition> LaneGraph::locate_if(double x, double y, std::optional<double> heading,
                                                 double max_distance,
                                                 const LaneFilter& accept) const {
  std::optional<LanePosition> best;
  double best_key0 = kInf, best_key1 = kInf;
  for (size_t r = 0; r < roads_.size(); ++r) {
    const RoadIndex& ri = roads_[r];
    if (x < ri.min_x - max_distance || x > ri.max_x + max_distance || y < ri.min_y - max_distance ||
        y > ri.max_y + max_distance) {
      continue;
    }
    const Road& road = net_->roads[r];
    // Nearest point of the reference polyline, then Newton steps on the true line.
    double s = 0, d_best = kInf;
    for (size_t i = 0; i + 1 < ri.points.size(); ++i) {
      const auto& a = ri.points[i];
      const auto& b = ri.points[i + 1];
      const double dx = b[0] - a[0], dy = b[1] - a[1];
      const double l2 = dx * dx + dy * dy;
      const double w = l2 > 0 ? std::clamp(((x - a[0]) * dx + (y - a[1]) * dy) / l2, 0.0, 1.0) : 0;
      const double d = std::hypot(a[0] + w * dx - x, a[1] + w * dy - y);
      if (d < d_best) {
        d_best = d;
        s = ri.stations[i] + w * (ri.stations[i + 1] - ri.stations[i]);
      }
    }
    if (ri.points.size() == 1) s = 0;
    Pose2 ref;
    for (int it = 0; it < 20; ++it) {
      ref = road.reference(s);
      const double ch = std::cos(ref.heading), sh = std::sin(ref.heading);
      const double along = (x - ref.x) * ch + (y - ref.y) * sh;
      const double across = -(x - ref.x) * sh + (y - ref.y) * ch;
      const double denom = 1 - ref.curvature * across;
      const double step = std::abs(denom) > 1e-6 ? along / denom : along;
      const double next = std::clamp(s + step, 0.0, road.length);
      if (std::abs(next - s) < 1e-10) break;
      s = next;
    }
    ref = road.reference(s);
    const double ch = std::cos(ref.heading), sh = std::sin(ref.heading);
    const double along = (x - ref.x) * ch + (y - ref.y) * sh;
    const double t = -(x - ref.x) * sh + (y - ref.y) * ch;
    const size_t k = road.section_index(s);
    for (const Lane& lane : road.sections[k].lanes) {
      if (lane.id == 0) continue;
      const LaneCentre c = centre(road, k, s, lane.id);
      const double lo = std::min(c.inner, c.outer), hi = std::max(c.inner, c.outer);
      if (hi - lo <= 1e-9) continue;
      const double lateral = t < lo ? lo - t : (t > hi ? t - hi : 0.0);
      const double dist = std::hypot(lateral, std::abs(along) > 1e-6 ? along : 0.0);
      if (dist > max_distance) continue;
      const LaneNode& n = lanes_[lane_in_section(r, k, lane.id)];
      const Pose2 p = offset_pose(road, s, c.t, c.slope);
      const double lane_heading = wrap(p.heading + (n.forward ? 0 : std::numbers::pi));
      if (accept && !accept(n, lane_heading)) continue;
      const double key0 = dist > 1e-9 ? dist : 0.0;
      const double key1 = heading ? std::abs(wrap(*heading - lane_heading)) : std::abs(t - c.t);
      if (key0 < best_key0 - 1e-9 ||
          (std::abs(key0 - best_key0) <= 1e-9 && key1 < best_key1 - 1e-12)) {
        best_key0 = key0;
        best_key1 = key1;
        best = LanePosition{n.index, road.id, lane.id, s, t - c.t, t, lane_heading, key0};
      }
    }
  }
  return best;
}

SpeedLimit LaneGraph::speed_limit(LaneIndex lane, double s) const {
  const LaneNode& n = lanes_.at(lane);
  const Lane* l = n.road->sections[n.section].find_lane(n.lane_id);
  const SpeedRecord* rec = nullptr;
  for (const SpeedRecord& r : l->speeds) {
    if (r.start <= s + 1e-9) rec = &r;
  }
  if (!rec) {
    for (const SpeedRecord& r : n.road->speed_limits) {
      if (r.start <= s + 1e-9) rec = &r;
    }
  }
  if (!rec || std::isnan(rec->max_mps)) return {};
  return {rec->max_mps, true};
}

std::vector<LaneIndex> LaneGraph::sidewalks() const {
  std::vector<LaneIndex> out;
  for (const LaneNode& n : lanes_) {
    if (n.type == "sidewalk") out.push_back(n.index);
  }
  return out;
}

std::vector<const SignalInfo*> LaneGraph::junction_signals(const std::string& junction_id) const {
  std::vector<const SignalInfo*> out;
  for (const SignalInfo& g : signals_) {
    if (g.junction == junction_id) out.push_back(&g);
  }
  return out;
}

}  // namespace convoy::opendrive
