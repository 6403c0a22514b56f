#include "traffic_pool/pool.h"

#include <algorithm>
#include <cmath>

#include "road_users/lights.h"

namespace convoy::traffic_pool {

using road_users::Light;

namespace {
uint64_t splitmix(uint64_t& state) {
  uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
constexpr double kStopMargin = 0.5;   // m before the stop line
constexpr double kLookAhead = 150;    // m of lanes ahead searched for a leader
constexpr double kMaxDecel = 9;       // m/s^2
constexpr int kMobilEverySteps = 20;  // a vehicle considers a lane change this often
}  // namespace

uint32_t Pool::choose(size_t i, uint32_t lane) {
  if (lane == kNone) return kNone;
  const std::vector<uint32_t>& next = net_.lane(lane).next;
  if (next.empty()) return kNone;
  std::vector<uint32_t>& route = route_[i];
  if (!route.empty()) {
    const uint32_t want = route.back();
    route.pop_back();
    if (std::find(next.begin(), next.end(), want) != next.end()) return want;
    route.clear();  // off its route: onward from here
  }
  // Onward: a draw among the lanes that follow, turning back only where nothing else goes on.
  uint32_t keep[8];
  size_t k = 0;
  for (uint32_t n : next) {
    if (!net_.lane(n).u_turn && k < 8) keep[k++] = n;
  }
  if (k == 0) return next[splitmix(rng_[i]) % next.size()];
  return keep[splitmix(rng_[i]) % k];
}

// Per lane, its entries (pooled vehicles and externals' lane entries) sorted by s.
void Pool::index_lanes() {
  const size_t nl = net_.lanes().size();
  lane_begin_.assign(nl + 1, 0);
  for (uint32_t l : lane_) {
    if (l != kNone) ++lane_begin_[l + 1];
  }
  for (size_t k = 0; k < nl; ++k) lane_begin_[k + 1] += lane_begin_[k];
  std::vector<uint32_t> fill(lane_begin_.begin(), lane_begin_.end() - 1);
  order_.resize(lane_begin_[nl]);
  for (uint32_t i = 0; i < lane_.size(); ++i) {
    if (lane_[i] != kNone) order_[fill[lane_[i]]++] = i;
  }
  for (size_t k = 0; k < nl; ++k) {
    std::sort(order_.begin() + lane_begin_[k], order_.begin() + lane_begin_[k + 1],
              [&](uint32_t a, uint32_t b) { return s_[a] < s_[b] || (s_[a] == s_[b] && a < b); });
  }
  rank_.assign(lane_.size(), kNone);
  for (uint32_t r = 0; r < order_.size(); ++r) rank_[order_[r]] = r;
}

// The grid holds the pooled vehicles and one entry per external road user.
void Pool::build_grid() {
  gx_ = std::max(1, static_cast<int>((net_.max_x - net_.min_x + 40) / cell_) + 1);
  gy_ = std::max(1, static_cast<int>((net_.max_y - net_.min_y + 40) / cell_) + 1);
  cell_head_.assign(static_cast<size_t>(gx_) * gy_, kNone);
  cell_next_.assign(grid_end_, kNone);
  for (uint32_t i = 0; i < grid_end_; ++i) {
    if (i < n_ && lane_[i] == kNone) continue;  // absent (a flow's vehicle not in yet or gone)
    const int cx = std::clamp(static_cast<int>((x_[i] - net_.min_x + 20) / cell_), 0, gx_ - 1);
    const int cy = std::clamp(static_cast<int>((y_[i] - net_.min_y + 20) / cell_), 0, gy_ - 1);
    const size_t c = static_cast<size_t>(cy) * gx_ + cx;
    cell_next_[i] = cell_head_[c];
    cell_head_[c] = i;
  }
}

double Pool::leader_gap(size_t i, double& vl) const {
  const uint32_t l = lane_[i];
  const uint32_t r = rank_[i];
  if (r + 1 < lane_begin_[l + 1]) {
    const uint32_t j = order_[r + 1];
    vl = v_[j];
    return s_[j] - specs_[j].length - s_[i];
  }
  double dist = net_.lane(l).length - s_[i];
  for (uint32_t n : {next_[i], next2_[i]}) {
    if (n == kNone || dist > kLookAhead) break;
    if (lane_begin_[n + 1] > lane_begin_[n]) {
      const uint32_t j = order_[lane_begin_[n]];
      vl = v_[j];
      return dist + s_[j] - specs_[j].length;
    }
    dist += net_.lane(n).length;
  }
  return INFINITY;
}

bool Pool::conflict_free(uint32_t junction_lane, size_t me) const {
  for (uint32_t c : net_.lane(junction_lane).conflicts) {
    if (claims_[c] > 0 || external_arriving(c)) return false;
    for (uint32_t r = lane_begin_[c]; r < lane_begin_[c + 1]; ++r) {
      if (order_[r] != me) return false;
    }
  }
  return true;
}

bool Pool::exit_has_room(uint32_t exit_lane, double need) const {
  if (exit_lane == kNone || net_.lane(exit_lane).junction >= 0) return true;
  if (lane_begin_[exit_lane + 1] == lane_begin_[exit_lane]) return true;
  const uint32_t j = order_[lane_begin_[exit_lane]];
  return s_[j] - specs_[j].length > need;
}

// The gap to the stop line (the lane's end, or before its crosswalk: PoolLane::stop_back) when
// it must wait there, else infinity. A vehicle of an approach
// (its leader's claim does not stop it: a lane does not conflict with itself) claims its junction
// lane once it is within its braking distance (+5 m) of the line with a green light, no crossing or
// merging lane claimed or occupied, and room behind the exit lane's last vehicle; from then on it
// is committed.
double Pool::junction_gap(size_t i) {
  const uint32_t l = lane_[i];
  const PoolLane& lane = net_.lane(l);
  const uint32_t j = next_[i];
  if (lane.approach < 0 || j == kNone || claim_[i] == j) return INFINITY;
  const double dist = lane.length - s_[i];
  if (dist > 80) return INFINITY;
  const VehicleSpec& sp = specs_[i];
  const double brake = v_[i] * v_[i] / (2 * sp.idm.b);
  // Its stop line: before the crosswalk, unless its front is past that already.
  const double line = dist > lane.stop_back ? dist - lane.stop_back : dist;
  const Light light = this->light(l, j);
  const bool stop_light = light == Light::kRed || light == Light::kRedYellow ||
                          (light == Light::kYellow && line > brake);
  if (stop_light) return line - kStopMargin;
  if (!conflict_free(j, i) || !exit_has_room(next2_[i], sp.length + sp.idm.s0)) {
    return line - kStopMargin;
  }
  if (dist < std::max(brake + 5, 8.0)) {
    if (claim_[i] != kNone) --claims_[claim_[i]];
    claim_[i] = j;
    ++claims_[j];
  }
  return INFINITY;
}

// Inside a junction: the nearest vehicle ahead in its path's corridor, whatever lane it is on.
double Pool::grid_gap(size_t i, double& vl) const {
  const double c = std::cos(yaw_[i]), sn = std::sin(yaw_[i]);
  const VehicleSpec& me = specs_[i];
  double best = INFINITY;
  for_near(x_[i], y_[i], 15, [&](uint32_t k) {
    if (k == i || lane_[k] == lane_[i]) return;
    const double dx = (x_[k] - x_[i]) * c + (y_[k] - y_[i]) * sn;
    const double dy = -(x_[k] - x_[i]) * sn + (y_[k] - y_[i]) * c;
    if (dx <= 0 || std::abs(dy) > 0.5 * (me.width + specs_[k].width) + 0.2) return;
    const double gap = dx - 0.5 * (me.length + specs_[k].length);
    if (gap < best) {
      best = gap;
      vl = v_[k] * std::cos(yaw_[k] - yaw_[i]);
    }
  });
  return best;
}

double Pool::accel_of(size_t i) {
  const VehicleSpec& sp = specs_[i];
  double vl = 0;
  double gap = leader_gap(i, vl);
  const double jg = junction_gap(i);
  if (jg < gap) {
    gap = jg;
    vl = 0;
  }
  if (net_.lane(lane_[i]).junction >= 0) {
    double vg = 0;
    const double gg = grid_gap(i, vg);
    if (gg < gap) {
      gap = gg;
      vl = vg;
    }
  }
  const double v0 = std::min(sp.idm.v0, net_.lane(lane_[i]).limit);
  return std::clamp(sp.idm.accel(v_[i], gap, vl, v0), -kMaxDecel, sp.idm.a);
}

void Pool::consider_lane_change(size_t i) {
  const uint32_t l = lane_[i];
  const PoolLane& lane = net_.lane(l);
  const VehicleSpec& sp = specs_[i];
  if (!mobil_[i] || lane.junction >= 0 || claim_[i] != kNone) return;
  if (s_[i] < sp.length + 2 || lane.length - s_[i] < 30) return;
  road_users::LaneNeighbours cur;
  double vl = 0;
  cur.leader.gap = leader_gap(i, vl);
  cur.leader.found = std::isfinite(cur.leader.gap);
  cur.leader.speed = vl;
  if (rank_[i] > lane_begin_[l]) {
    const uint32_t f = order_[rank_[i] - 1];
    cur.follower = {true, s_[i] - sp.length - s_[f], v_[f]};
  }
  const double v0 = std::min(sp.idm.v0, lane.limit);
  uint32_t best = kNone;
  double best_gain = -INFINITY, best_s = 0;
  for (uint32_t t : {lane.left, lane.right}) {
    if (t == kNone || changed_into_[t]) continue;
    const PoolLane& tl = net_.lane(t);
    const double st = s_[i] * tl.length / lane.length;
    if (tl.length - st < 30) continue;
    road_users::LaneNeighbours tgt;
    const auto b = order_.begin() + lane_begin_[t], e = order_.begin() + lane_begin_[t + 1];
    const auto it = std::upper_bound(b, e, st, [&](double v, uint32_t k) { return v < s_[k]; });
    if (it != e) tgt.leader = {true, s_[*it] - specs_[*it].length - st, v_[*it]};
    if (it != b) tgt.follower = {true, st - sp.length - s_[*(it - 1)], v_[*(it - 1)]};
    if (tgt.leader.found && tgt.leader.gap < 2) continue;
    if (tgt.follower.found && tgt.follower.gap < 2) continue;
    const road_users::MobilDecision d =
        road_users::decide_lane_change(sp.idm, sp.mobil, v_[i], v0, sp.length, cur, tgt);
    if (d.outcome == road_users::LaneChange::kChange && d.incentive > best_gain) {
      best = t;
      best_gain = d.incentive;
      best_s = st;
    }
  }
  if (best == kNone) return;
  changed_into_[best] = 1;
  lane_[i] = best;
  prev_[i] = kNone;
  s_[i] = best_s;
  route_[i].clear();
  next_[i] = choose(i, best);
  next2_[i] = choose(i, next_[i]);
  ++stats_.lane_changes;
}

void Pool::advance(size_t i, double dt) {
  const double a = acc_[i], v = v_[i];
  double v1 = v + a * dt, ds = 0.5 * (v + v1) * dt;
  if (v1 < 0) {
    ds = a < 0 ? v * v / (-2 * a) : 0;
    v1 = 0;
  }
  v_[i] = v1;
  s_[i] += ds;
  while (s_[i] > net_.lane(lane_[i]).length) {
    const uint32_t n = next_[i];
    if (n == kNone) {
      respawn(i);
      return;
    }
    s_[i] -= net_.lane(lane_[i]).length;
    if (net_.lane(n).junction >= 0) {
      ++stats_.junction_entries;
      if (claim_[i] != n) {  // could not stop in time: it takes the lane anyway
        if (claim_[i] != kNone) --claims_[claim_[i]];
        claim_[i] = n;
        ++claims_[n];
      }
    }
    prev_[i] = lane_[i];
    lane_[i] = n;
    next_[i] = next2_[i];
    next2_[i] = choose(i, next_[i]);
  }
  const uint32_t c = claim_[i];
  if (c != kNone && lane_[i] != c && net_.lane(lane_[i]).junction < 0 &&
      net_.lane(lane_[i]).approach != net_.lane(c).junction && s_[i] >= specs_[i].length) {
    --claims_[c];  // its rear has left the junction lane
    claim_[i] = kNone;
  }
}

void Pool::update_pose(size_t i) {
  const PoolLane& lane = net_.lane(lane_[i]);
  const double c = s_[i] - 0.5 * specs_[i].length;
  if (c < 0 && prev_[i] != kNone) {  // its centre is still on the lane it came from
    const PoolLane& prev = net_.lane(prev_[i]);
    const opendrive::Pose2 p = prev.at(prev.length + c);
    x_[i] = p.x;
    y_[i] = p.y;
    yaw_[i] = p.heading;
    return;
  }
  const opendrive::Pose2 p = lane.at(std::max(c, 0.0));
  x_[i] = p.x;
  y_[i] = p.y;
  yaw_[i] = p.heading;
  if (c < 0) {
    x_[i] += c * std::cos(p.heading);
    y_[i] += c * std::sin(p.heading);
  }
}

void Pool::step(double dt) {
  place_externals();
  index_lanes();
  build_grid();
  changed_into_.assign(net_.lanes().size(), 0);
  const uint64_t tick = static_cast<uint64_t>(std::llround(t_ / dt));
  for (size_t i = 0; i < size(); ++i) {
    if (present(i)) acc_[i] = accel_of(i);
  }
  for (size_t i = 0; i < size(); ++i) {
    if (present(i) && (tick + i) % kMobilEverySteps == 0 && !commanded_lateral(i))
      consider_lane_change(i);
  }
  if (has_commands_) command_before_move(dt);
  for (size_t i = 0; i < size(); ++i) {
    if (!present(i) || on_polyline(i)) continue;  // (driven along it by the command)
    advance(i, dt);
    if (!present(i)) continue;  // it left the network
    update_pose(i);
  }
  if (has_commands_) command_after_move(dt);
  step_walkers(dt);
  if (has_commands_) command_walkers_after(dt);
  t_ += dt;
}

}  // namespace convoy::traffic_pool
