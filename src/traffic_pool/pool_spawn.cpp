// The pool's set-up: checking and placing the road users, spawning a count of them, putting a
// vehicle that reached a dead end back on the network, and the box overlap test.
#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "traffic_pool/draw.h"
#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {

namespace {
std::string who(const VehicleSpec& v) { return "road user '" + v.id + "'"; }
}  // namespace

bool boxes_overlap(double ax, double ay, double ayaw, double al, double aw, double bx, double by,
                   double byaw, double bl, double bw) {
  const double axes[4][2] = {{std::cos(ayaw), std::sin(ayaw)},
                             {-std::sin(ayaw), std::cos(ayaw)},
                             {std::cos(byaw), std::sin(byaw)},
                             {-std::sin(byaw), std::cos(byaw)}};
  const double dx = bx - ax, dy = by - ay;
  for (const auto& u : axes) {
    auto extent = [&](double yaw, double l, double w) {
      return 0.5 * l * std::abs(u[0] * std::cos(yaw) + u[1] * std::sin(yaw)) +
             0.5 * w * std::abs(-u[0] * std::sin(yaw) + u[1] * std::cos(yaw));
    };
    if (std::abs(dx * u[0] + dy * u[1]) > extent(ayaw, al, aw) + extent(byaw, bl, bw)) {
      return false;
    }
  }
  return true;
}

Pool::Pool(const PoolNetwork& net, std::vector<VehicleSpec> specs, double cell_m)
    : net_(net), specs_(std::move(specs)), cell_(cell_m) {
  const size_t n = specs_.size();
  n_ = grid_end_ = n;
  lane_.assign(n, kNone);
  prev_.assign(n, kNone);
  next_.assign(n, kNone);
  next2_.assign(n, kNone);
  claim_.assign(n, kNone);
  s_.assign(n, 0);
  v_.assign(n, 0);
  acc_.assign(n, 0);
  x_.assign(n, 0);
  y_.assign(n, 0);
  yaw_.assign(n, 0);
  rng_.assign(n, 0);
  route_.assign(n, {});
  mobil_.assign(n, 0);
  claims_.assign(net_.lanes().size(), 0);
  std::vector<uint8_t> led_into(net_.lanes().size(), 0);
  for (const PoolLane& l : net_.lanes()) {
    for (uint32_t k : l.next) led_into[k] = 1;
  }
  for (uint32_t l = 0; l < net_.lanes().size(); ++l) {
    if (!led_into[l] && net_.lane(l).junction < 0) entries_.push_back(l);
  }
  validate();
  for (size_t i = 0; i < n; ++i) place(i);
  changed_into_.assign(net_.lanes().size(), 0);
  index_lanes();
  build_grid();
  const auto o = overlaps();
  if (!o.empty()) {
    const VehicleSpec& a = specs_[o[0].first];
    const VehicleSpec& b = specs_[o[0].second];
    std::ostringstream m;
    m << who(a) << " and road user '" << b.id << "' are on one spot (road " << a.road << " lane "
      << a.lane << " s " << a.s << ", road " << b.road << " lane " << b.lane << " s " << b.s
      << "): their boxes overlap";
    throw PoolError(m.str());
  }
}

void Pool::validate() {
  std::set<std::string> ids;
  for (const VehicleSpec& v : specs_) {
    if (v.id.empty()) throw PoolError("a road user has no id");
    if (!ids.insert(v.id).second) throw PoolError(who(v) + " is listed twice");
    if (std::find_if(std::begin(kPolicies), std::end(kPolicies),
                     [&](const char* p) { return v.policy == p; }) == std::end(kPolicies)) {
      throw PoolError(who(v) + ": unknown policy '" + v.policy + "' (known: idm_mobil, idm)");
    }
    if (!(v.length > 0.5 && v.width > 0.3)) {
      throw PoolError(who(v) + ": length and width must be > 0.5 m and > 0.3 m");
    }
    if (!(v.idm.v0 > 0 && v.idm.a > 0 && v.idm.b > 0 && v.idm.T >= 0 && v.idm.s0 >= 0)) {
      throw PoolError(who(v) + ": IDM parameters must be positive (v0, a, b; T, s0 >= 0)");
    }
  }
}

// Puts vehicle i at its start (road, lane, s along the driving direction), walking on through
// the lanes that follow while s is beyond a lane's end, and plans its route.
void Pool::place(size_t i) {
  const VehicleSpec& v = specs_[i];
  if (v.absent) return;  // until enter()
  const opendrive::LaneGraph& g = net_.graph();
  opendrive::LaneIndex gl = opendrive::kNoLane;
  try {
    gl = g.entry_lane(v.road, v.lane);
  } catch (const std::exception&) {
  }
  uint32_t l = gl == opendrive::kNoLane ? kNone : net_.pool_lane(gl);
  if (v.pool_lane < net_.lanes().size()) l = v.pool_lane;
  if (l == kNone) {
    throw PoolError(who(v) + ": road '" + v.road + "' lane " + std::to_string(v.lane) +
                    " is not a driving lane of the map");
  }
  double s = v.s;
  if (!(s >= 0)) throw PoolError(who(v) + ": s must be >= 0");
  if (l == v.pool_lane && s > net_.lane(l).length) {
    throw PoolError(who(v) + ": s is beyond its lane");
  }
  while (s > net_.lane(l).length) {
    s -= net_.lane(l).length;
    const PoolLane& cur = net_.lane(l);
    if (cur.next.empty() || net_.lane(cur.next[0]).road_id != v.road) {
      throw PoolError(who(v) + ": s " + std::to_string(v.s) + " is beyond road '" + v.road +
                      "' lane " + std::to_string(v.lane));
    }
    l = cur.next[0];
  }
  lane_[i] = l;
  s_[i] = s;
  v_[i] = std::max(0.0, v.speed);
  rng_[i] = mix(v.seed);
  mobil_[i] = v.policy == "idm_mobil" && !v.to;
  plan_route(i, l, s);
  next_[i] = choose(i, l);
  next2_[i] = choose(i, next_[i]);
  update_pose(i);
}

// Its route (lanes still to drive) from s on pool lane l to its spec's destination, if any.
void Pool::plan_route(size_t i, uint32_t l, double s) {
  const VehicleSpec& v = specs_[i];
  const opendrive::LaneGraph& g = net_.graph();
  route_[i].clear();
  if (v.to) {
    opendrive::LaneIndex to = opendrive::kNoLane;
    try {
      to = g.exit_lane(v.to->first, v.to->second);
    } catch (const std::exception&) {
    }
    const PoolLane& pl = net_.lane(l);
    const opendrive::LaneNode& n = g.lane(pl.graph_lane);
    opendrive::RouteOptions opt;
    opt.lane_changes = false;
    std::optional<opendrive::LaneRoute> r;
    if (to != opendrive::kNoLane) {
      const opendrive::LaneNode& tn = g.lane(to);
      r = g.route(pl.graph_lane, n.forward ? n.s0 + s : n.s1 - s, to, tn.forward ? tn.s1 : tn.s0,
                  opt);
    }
    if (!r) {
      throw PoolError(who(v) + ": no path from road '" + pl.road_id + "' lane " +
                      std::to_string(pl.lane_id) + " to road '" + v.to->first + "' lane " +
                      std::to_string(v.to->second));
    }
    for (size_t k = r->segments.size(); k-- > 1;) {
      const uint32_t p = net_.pool_lane(r->segments[k].lane);
      if (p != kNone) route_[i].push_back(p);
    }
  }
}

// Whether vehicle i could start, standing, at s on lane l: no vehicle ahead on the lane within
// s0 + 5 m, nobody's box within 2 * (s0 + 1) m ahead or behind, or 0.3 m beside (a vehicle on
// the next lane, or queued on the lane out of the map beside an entry, does not block it), and
// nobody entered the lane this step (the lanes' lists are the step's).
bool Pool::start_free(size_t i, uint32_t l, double s) const {
  const VehicleSpec& v = specs_[i];
  const PoolLane& lane = net_.lane(l);
  if (lane.junction >= 0 || lane.length < 2 * v.length + 20 || changed_into_[l]) return false;
  bool free = true;
  if (lane_begin_[l + 1] > lane_begin_[l]) {
    const uint32_t j = order_[lane_begin_[l]];
    free = s_[j] - specs_[j].length > s + v.idm.s0 + 5;
  }
  const opendrive::Pose2 p = lane.at(s - 0.5 * v.length);
  const double clear_l = v.length + 4 * (v.idm.s0 + 1), clear_w = v.width + 0.6;
  for_near(p.x, p.y, 0.5 * clear_l + 8, [&](uint32_t k) {
    if (k != i && boxes_overlap(p.x, p.y, p.heading, clear_l, clear_w, x_[k], y_[k], yaw_[k],
                                specs_[k].length, specs_[k].width)) {
      free = false;
    }
  });
  return free;
}

void Pool::start_at(size_t i, uint32_t l, double s) {
  if (claim_[i] != kNone) --claims_[claim_[i]];
  claim_[i] = kNone;
  changed_into_[l] = 1;
  lane_[i] = l;
  prev_[i] = kNone;
  s_[i] = s;
  v_[i] = 0;
}

// A vehicle at a dead end (it leaves the map) starts again, standing, at the start of a lane
// drawn by its seed whose first metres are free: one of the map's entries (lanes no lane leads
// into) when it has some, else any lane; it waits at the dead end while none of 16 draws is.
// With leave_at_exits it leaves the network instead (absent).
void Pool::respawn(size_t i) {
  const VehicleSpec& v = specs_[i];
  if (leave_at_exits_) {
    if (claim_[i] != kNone) --claims_[claim_[i]];
    claim_[i] = kNone;
    lane_[i] = prev_[i] = next_[i] = next2_[i] = kNone;
    v_[i] = 0;
    return;
  }
  const size_t nl = entries_.empty() ? net_.lanes().size() : entries_.size();
  for (int attempt = 0; attempt < 16; ++attempt) {
    const size_t draw = mix(rng_[i] += 0x51ed27) % nl;
    const uint32_t l = entries_.empty() ? static_cast<uint32_t>(draw) : entries_[draw];
    const double s = v.length + 1;
    if (!start_free(i, l, s)) continue;
    start_at(i, l, s);
    route_[i].clear();
    next_[i] = choose(i, l);
    next2_[i] = choose(i, next_[i]);
    ++stats_.respawns;
    return;
  }
  s_[i] = net_.lane(lane_[i]).length;
  v_[i] = 0;
}

bool Pool::enter(size_t i, uint32_t l) {
  const VehicleSpec& v = specs_[i];
  if (present(i)) throw PoolError(who(v) + ": enters the network while on it");
  if (l >= net_.lanes().size() || net_.lane(l).junction >= 0) {
    throw PoolError(who(v) + ": enters on a lane that is not a driving lane outside junctions");
  }
  const double s = v.length + 1;
  if (!start_free(i, l, s)) return false;
  rng_[i] = mix(v.seed);
  mobil_[i] = v.policy == "idm_mobil" && !v.to;
  plan_route(i, l, s);  // throws (before the vehicle is placed) when `to` has no path
  start_at(i, l, s);
  next_[i] = choose(i, l);
  next2_[i] = choose(i, next_[i]);
  update_pose(i);
  return true;
}

std::vector<std::pair<uint32_t, uint32_t>> Pool::overlaps() const {
  std::vector<std::pair<uint32_t, uint32_t>> out;
  for (uint32_t i = 0; i < size(); ++i) {
    if (!present(i)) continue;
    const VehicleSpec& a = specs_[i];
    for_near(x_[i], y_[i], 0.5 * a.length + 8, [&](uint32_t k) {
      if (k <= i || k >= n_) return;
      const VehicleSpec& b = specs_[k];
      if (boxes_overlap(x_[i], y_[i], yaw_[i], a.length, a.width, x_[k], y_[k], yaw_[k], b.length,
                        b.width)) {
        out.emplace_back(i, k);
      }
    });
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::pair<uint32_t, uint32_t>> Pool::external_overlaps() const {
  std::vector<std::pair<uint32_t, uint32_t>> out;
  for (uint32_t k = static_cast<uint32_t>(n_); k < grid_end_; ++k) {
    if (ext_of_[k - n_] >= ext_.size()) continue;  // a walker's
    const VehicleSpec& b = specs_[k];
    for_near(x_[k], y_[k], 0.5 * b.length + 8, [&](uint32_t i) {
      if (i >= n_ || !present(i)) return;
      const VehicleSpec& a = specs_[i];
      if (boxes_overlap(x_[i], y_[i], yaw_[i], a.length, a.width, x_[k], y_[k], yaw_[k], b.length,
                        b.width)) {
        out.emplace_back(i, ext_of_[k - n_]);
      }
    });
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::pair<uint32_t, uint32_t>> Pool::walker_overlaps() const {
  std::vector<std::pair<uint32_t, uint32_t>> out;
  if (!walkers_) return out;
  const PoolWalkers& w = *walkers_;
  for (uint32_t k = 0; k < w.size(); ++k) {
    const WalkerSpec& b = w.spec(k);
    for_near(w.x(k), w.y(k), 8, [&](uint32_t i) {
      if (i >= n_ || !present(i)) return;
      const VehicleSpec& a = specs_[i];
      if (boxes_overlap(x_[i], y_[i], yaw_[i], a.length, a.width, w.x(k), w.y(k), w.yaw(k),
                        b.length, b.width)) {
        out.emplace_back(i, k);
      }
    });
  }
  std::sort(out.begin(), out.end());
  return out;
}

namespace {
std::vector<std::pair<uint32_t, double>> slots_of(const PoolNetwork& net, const VehicleSpec& base,
                                                  const std::vector<ClearZone>& keep_clear) {
  const double spacing = base.length + base.idm.s0 + 2;
  std::vector<std::pair<uint32_t, double>> slots;
  for (uint32_t l = 0; l < net.lanes().size(); ++l) {
    const PoolLane& lane = net.lane(l);
    if (lane.junction >= 0) continue;
    for (double s = base.length + 1; s <= lane.length - 1; s += spacing) {
      const opendrive::Pose2 p = lane.at(s - 0.5 * base.length);
      const bool clear = std::none_of(
          keep_clear.begin(), keep_clear.end(),
          [&](const ClearZone& z) { return std::hypot(p.x - z.x, p.y - z.y) < z.radius; });
      if (clear) slots.emplace_back(l, s);
    }
  }
  return slots;
}
}  // namespace

size_t spawn_capacity(const PoolNetwork& net, const VehicleSpec& base,
                      const std::vector<ClearZone>& keep_clear) {
  return slots_of(net, base, keep_clear).size();
}

double driving_km(const PoolNetwork& net) {
  double m = 0;
  for (const PoolLane& lane : net.lanes()) {
    if (lane.junction < 0) m += lane.length;
  }
  return m / 1000;
}

std::vector<VehicleSpec> spawn(const PoolNetwork& net, size_t count, uint64_t seed,
                               const VehicleSpec& base, const std::string& prefix,
                               const std::vector<ClearZone>& keep_clear) {
  const double spacing = base.length + base.idm.s0 + 2;
  std::vector<std::pair<uint32_t, double>> slots = slots_of(net, base, keep_clear);
  if (count > slots.size()) {
    std::ostringstream m;
    m << "road user '" << prefix << slots.size() << "': a count of " << count
      << " cannot fit the network: its driving lanes outside junctions hold at most "
      << slots.size() << " vehicles " << spacing << " m apart";
    throw PoolError(m.str());
  }
  shuffle_by_seed(slots, seed);
  std::vector<VehicleSpec> out;
  out.reserve(count);
  for (size_t k = 0; k < count; ++k) {
    VehicleSpec v = base;
    const PoolLane& lane = net.lane(slots[k].first);
    v.id = prefix + std::to_string(k);
    v.seed = seed + k;
    v.road = lane.road_id;
    v.lane = lane.lane_id;
    v.s = slots[k].second;
    v.pool_lane = slots[k].first;
    out.push_back(std::move(v));
  }
  return out;
}

}  // namespace convoy::traffic_pool
