// Pooled walkers' set-up and trips (pool_walkers.h): the sidewalk networks and the crosswalks on
// reach of each, spawning on the sidewalks, and drawing a walker's next trip.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "traffic_pool/draw.h"
#include "traffic_pool/pool.h"
#include "traffic_pool/pool_walkers.h"

namespace convoy::traffic_pool {

namespace odr = convoy::opendrive;
namespace ru = convoy::road_users;

namespace {
constexpr double kTripReach = 300;  // m: crosswalks this near are drawn first
constexpr double kLightReach = 30;  // m from a crosswalk to the stop line of its road's approach

bool is_sidewalk(const odr::LaneGraph& g, odr::LaneIndex l) {
  return l != odr::kNoLane && g.lane(l).type == "sidewalk";
}

// Slots kWalkerSpacing m apart along every sidewalk lane (road s), outside the `keep_clear` discs.
std::vector<ru::Spot> walker_slots(const PoolNetwork& net,
                                   const std::vector<ClearZone>& keep_clear) {
  const odr::LaneGraph& g = net.graph();
  std::vector<ru::Spot> slots;
  for (const odr::LaneNode& n : g.lanes()) {
    if (n.type != "sidewalk" || n.length < 1 || !(n.s1 > n.s0)) continue;
    const double per_s = (n.s1 - n.s0) / n.length;
    for (double a = 0.5 * kWalkerSpacing; a <= n.length - 0.5; a += kWalkerSpacing) {
      const double s = n.s0 + a * per_s;
      const odr::WorldPose p = g.world_pose(n.road->id, n.lane_id, s);
      const bool clear = std::none_of(
          keep_clear.begin(), keep_clear.end(),
          [&](const ClearZone& z) { return std::hypot(p.x - z.x, p.y - z.y) < z.radius; });
      if (clear) slots.push_back({n.index, s});
    }
  }
  return slots;
}
}  // namespace

double sidewalk_km(const PoolNetwork& net) {
  double m = 0;
  for (const odr::LaneNode& n : net.graph().lanes()) {
    if (n.type == "sidewalk") m += n.length;
  }
  return m / 1000;
}

size_t walker_capacity(const PoolNetwork& net, const std::vector<ClearZone>& keep_clear) {
  return walker_slots(net, keep_clear).size();
}

std::vector<WalkerSpec> spawn_walkers(const PoolNetwork& net, size_t count, uint64_t seed,
                                      const std::string& prefix,
                                      const std::vector<ClearZone>& keep_clear) {
  std::vector<ru::Spot> slots = walker_slots(net, keep_clear);
  if (count > slots.size()) {
    char m[300];
    std::snprintf(m, sizeof m,
                  "road user '%s%zu': a count of %zu pedestrians cannot fit the map: its %.2f km "
                  "of sidewalk hold at most %zu walkers %g m apart",
                  prefix.c_str(), slots.size(), count, sidewalk_km(net), slots.size(),
                  kWalkerSpacing);
    throw PoolError(m);
  }
  shuffle_by_seed(slots, mix(seed ^ 0x77a1c3e5ULL));  // not the vehicles' draw
  std::vector<WalkerSpec> out(count);
  for (size_t k = 0; k < count; ++k) {
    WalkerSpec& w = out[k];
    w.id = prefix + std::to_string(k);
    w.seed = seed + k;
    w.lane = slots[k].lane;
    w.s = slots[k].s;
    uint64_t state = mix(w.seed);
    w.speed = uniform(state, 1.2, 1.5);
    w.gap = uniform(state, 3.5, 5.0);
  }
  return out;
}

PoolWalkers::PoolWalkers(const PoolNetwork& net, std::vector<WalkerSpec> specs)
    : net_(net), specs_(std::move(specs)), w_(specs_.size()) {
  const odr::LaneGraph& g = net_.graph();
  std::set<std::string> ids;
  for (const WalkerSpec& s : specs_) {
    const std::string who = "road user '" + s.id + "'";
    if (s.id.empty()) throw PoolError("a walker has no id");
    if (!ids.insert(s.id).second) throw PoolError(who + " is listed twice");
    if (s.lane >= g.lanes().size() || !is_sidewalk(g, s.lane)) {
      throw PoolError(who + ": its start is not on a sidewalk lane of the map");
    }
    if (!(s.speed > 0 && s.gap >= 0 && s.length > 0 && s.width > 0 && s.stride > 0)) {
      throw PoolError(who + ": speed, length, width and stride must be > 0, gap >= 0");
    }
  }
  index_sidewalks();
  for (size_t i = 0; i < w_.size(); ++i) {
    w_[i].rng = mix(specs_[i].seed ^ 0x3c6ef372fe94f82bULL);
    const odr::LaneNode& n = g.lane(specs_[i].lane);
    const odr::WorldPose p = g.world_pose(n.road->id, n.lane_id, specs_[i].s);
    w_[i].x = p.x;
    w_[i].y = p.y;
    w_[i].yaw = p.heading;
    first_trip(i);
    place(i, INFINITY);
  }
  index_walkers();
}

void PoolWalkers::first_trip(size_t i) {
  const WalkerSpec& s = specs_[i];
  if (s.crosswalk.empty()) {
    plan_trip(i, {s.lane, s.s});
    return;
  }
  ++stats_.trips;
  const odr::LaneGraph& g = net_.graph();
  for (size_t k = 0; k < crosswalks_.size(); ++k) {
    if (g.crosswalks()[crosswalks_[k].graph_index].id != s.crosswalk) continue;
    if (plan_crossing(i, {s.lane, s.s}, static_cast<int>(k))) return;
    throw PoolError("road user '" + s.id + "': crosswalk '" + s.crosswalk +
                    "' cannot be reached along the sidewalks from its start");
  }
  throw PoolError("road user '" + s.id + "': the map has no crosswalk '" + s.crosswalk +
                  "' with sidewalks at both ends");
}

// Sidewalk networks (lanes joined end to end), and per network the crosswalks with an end on
// it, each with the lights of the road it crosses.
void PoolWalkers::index_sidewalks() {
  const odr::LaneGraph& g = net_.graph();
  component_.assign(g.lanes().size(), -1);
  int n = 0;
  for (const odr::LaneNode& l : g.lanes()) {
    if (l.type != "sidewalk" || component_[l.index] >= 0) continue;
    std::vector<odr::LaneIndex> todo{l.index};
    component_[l.index] = n;
    while (!todo.empty()) {
      const odr::LaneNode& c = g.lane(todo.back());
      todo.pop_back();
      for (const auto* ends : {&c.at_start, &c.at_end}) {
        for (const odr::LaneEndRef& r : *ends) {
          if (!is_sidewalk(g, r.lane) || component_[r.lane] >= 0) continue;
          component_[r.lane] = n;
          todo.push_back(r.lane);
        }
      }
    }
    ++n;
  }
  reach_.assign(n, {});
  for (size_t k = 0; k < g.crosswalks().size(); ++k) {
    const odr::Crosswalk& c = g.crosswalks()[k];
    if (!is_sidewalk(g, c.ends[0]) || !is_sidewalk(g, c.ends[1])) continue;
    CrosswalkInfo info;
    info.graph_index = k;
    const odr::WorldPose a = g.world_pose(c.road_id, g.lane(c.ends[0]).lane_id, c.s);
    const odr::WorldPose b = g.world_pose(c.road_id, g.lane(c.ends[1]).lane_id, c.s);
    info.x = 0.5 * (a.x + b.x);
    info.y = 0.5 * (a.y + b.y);
    double best = kLightReach;
    for (uint32_t pl = 0; pl < net_.lanes().size(); ++pl) {
      const PoolLane& l = net_.lane(pl);
      if (l.road_id != c.road_id || l.poses.empty()) continue;
      const double d = std::hypot(l.poses.back().x - info.x, l.poses.back().y - info.y);
      if (l.approach >= 0 && !l.signals.empty() && d < kLightReach) info.lit.push_back(pl);
      if (l.group < 0) continue;
      if (d < best) {
        best = d;
        info.junction = l.approach;
        info.group = l.group;
      }
    }
    const int id = static_cast<int>(crosswalks_.size());
    crosswalks_.push_back(info);
    reach_[component_[c.ends[0]]].push_back(id);
    if (component_[c.ends[1]] != component_[c.ends[0]]) reach_[component_[c.ends[1]]].push_back(id);
  }
}

// Its next trip from `from`: to a crosswalk drawn among those on reach (the near ones first, not
// the one it has just crossed) and over it; else on along the sidewalks.
void PoolWalkers::plan_trip(size_t i, ru::Spot from) {
  Walker& w = w_[i];
  ++stats_.trips;
  const int comp = from.lane < component_.size() ? component_[from.lane] : -1;
  std::vector<int> near, all;
  if (comp >= 0) {
    for (int cw : reach_[comp]) {
      if (cw == w.last_crosswalk && reach_[comp].size() > 1) continue;
      all.push_back(cw);
      if (std::hypot(crosswalks_[cw].x - w.x, crosswalks_[cw].y - w.y) < kTripReach)
        near.push_back(cw);
    }
  }
  std::vector<int>& pick = near.empty() ? all : near;
  for (int attempt = 0; attempt < 3 && !pick.empty(); ++attempt) {
    w.rng = mix(w.rng);
    const size_t k = w.rng % pick.size();
    if (plan_crossing(i, from, pick[k])) return;
    pick.erase(pick.begin() + static_cast<std::ptrdiff_t>(k));
  }
  walk_on(i, w.x, w.y, w.yaw);
}

// A trip to crosswalk `cw`'s end on its side (the nearer along the sidewalks) and over it.
bool PoolWalkers::plan_crossing(size_t i, ru::Spot from, int cw) {
  const odr::LaneGraph& g = net_.graph();
  const odr::Crosswalk& c = g.crosswalks()[crosswalks_[cw].graph_index];
  std::optional<odr::LaneRoute> best;
  int side = 0;
  for (int d = 0; d < 2; ++d) {
    if (component_[c.ends[d]] != component_[from.lane]) continue;
    auto r = ru::walk(g, from, {c.ends[d], c.s});
    if (r && (!best || r->length < best->length)) {
      best = std::move(r);
      side = d;
    }
  }
  if (!best) return false;
  ru::WalkPlan p;
  p.before = std::move(best);
  p.cross = ru::CrossPlan{c.road_id, c.id, {c.ends[side], c.s}, {c.ends[1 - side], c.s}};
  ru::WalkPath path = ru::make_walk_path(g, p);
  if (path.length() < 1) return false;
  Walker& w = w_[i];
  w.path = std::move(path);
  w.arc = 0;
  w.committed = SIZE_MAX;
  w.last_crosswalk = cw;
  return true;
}

// On along the sidewalks the way it faces (forks drawn), for want of a crosswalk; where that
// goes nowhere, it starts again on a free sidewalk slot drawn by its seed.
void PoolWalkers::walk_on(size_t i, double x, double y, double yaw, bool may_respawn) {
  Walker& w = w_[i];
  w.rng = mix(w.rng);
  std::mt19937_64 rng(w.rng);
  ru::WalkPath path;
  ru::walk_path_from(net_.graph(), path, x, y, yaw, std::nullopt, rng);
  w.arc = 0;
  w.committed = SIZE_MAX;
  w.last_crosswalk = -1;
  if (path.length() >= 1 || !may_respawn) {
    w.path = std::move(path);
    if (w.path.poses.empty()) w.path.append({odr::Pose2{x, y, yaw}});  // it stands
    return;
  }
  const std::vector<ru::Spot> slots = walker_slots(net_, {});
  const odr::LaneGraph& g = net_.graph();
  for (int attempt = 0; attempt < 16 && !slots.empty(); ++attempt) {
    w.rng = mix(w.rng);
    const ru::Spot s = slots[w.rng % slots.size()];
    const odr::WorldPose p = g.world_pose(g.lane(s.lane).road->id, g.lane(s.lane).lane_id, s.s);
    const bool taken = std::any_of(w_.begin(), w_.end(), [&](const Walker& o) {
      return std::hypot(p.x - o.x, p.y - o.y) < 1;
    });
    if (taken) continue;
    ++stats_.respawns;
    w.x = p.x;
    w.y = p.y;
    walk_on(i, p.x, p.y, p.heading, false);
    return;
  }
  w.path = ru::WalkPath{};
  w.path.append({odr::Pose2{x, y, yaw}});  // it stands
}

}  // namespace convoy::traffic_pool
