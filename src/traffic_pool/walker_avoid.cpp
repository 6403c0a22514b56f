// Pooled walkers among each other (pool_walkers.h): a walker sidesteps, within the sidewalk's
// width, round one standing, crossing or coming towards it in its way, follows one going its way
// at its pace, and never steps to where its box would overlap another's.
#include <algorithm>
#include <cmath>

#include "road_users/pedestrian_behaviour.h"
#include "road_users/walker.h"
#include "traffic_pool/pool_walkers.h"

namespace convoy::traffic_pool {

namespace ru = convoy::road_users;

namespace {
constexpr double kReach = 0.4;      // m: the most it is off its path's centre on a sidewalk
constexpr double kOwnHalf = 0.2;    // m: the least right of a crossing leg's line it walks
constexpr double kClear = 0.72;     // m between two walkers' centres across its way to pass
constexpr double kAhead = 2.5;      // m: walkers this far ahead are sidestepped
constexpr double kBeside = 0.8;     // m: walkers this far behind it still bound its sidestep
constexpr double kFollowGap = 1.0;  // m: closer than this behind a walker, it keeps its pace
constexpr double kMoving = 0.3;     // m/s: slower than this, a walker is passed
constexpr double kSameWay = 0.5;    // cos of the most a walker followed heads off its way
constexpr double kSideRate = 0.6;   // m/s: its sidestep's pace
constexpr double kMargin = 0.05;    // m kept between two walkers' boxes
constexpr double kEscape = 0.9;     // m off its path's centre it may give way to
constexpr double kWay = 2.0;        // m: the way ahead of a walker on the road
constexpr double kBehindWay = 0.3;  // m: ... and behind it
constexpr int kMaxBlocks = 24;

// How far (x, y) is into the way ahead of a walker at (ox, oy) heading oyaw (kWay m long,
// 2 kClear wide), 0 outside it.
double in_way_of(double ox, double oy, double oyaw, double x, double y) {
  const double dx = x - ox, dy = y - oy, c = std::cos(oyaw), sn = std::sin(oyaw);
  const double lon = dx * c + dy * sn, lat = dx * sn - dy * c;
  return std::max(0.0, std::min({kClear - std::abs(lat), kWay - lon, lon + kBehindWay}));
}
}  // namespace

// The pace it may keep (from `v`) and the offset right of its path's centre it aims for
// (`target`): the nearest to its keep-right clear (kClear) of the walkers ahead it passes (not
// the ones going its way at a walk: it follows those), within kReach of the centre on a
// sidewalk, kKeepRight on the road (the crossing box vehicles stop for). Where there is no
// such offset it keeps its own and slows behind the ones in its way.
double PoolWalkers::avoid(size_t i, double v, double& target) const {
  const Walker& w = w_[i];
  const double c = std::cos(w.yaw), sn = std::sin(w.yaw);
  const double r = keep_right(i), r0 = r - w.dodge;
  const bool road = has_way(i);
  // On a crossing leg it keeps to its right half (the other half is the other way's), no
  // further right than kKeepRight (the crossing box vehicles stop for): it queues at the curb.
  double lo_b = -kReach, hi_b = kReach;
  if (current_crossing(i)) {
    lo_b = kOwnHalf;
    hi_b = ru::kKeepRight;
  }
  lo_b = std::min(lo_b, r);  // (off those bounds, where it is will do)
  hi_b = std::max(hi_b, r);
  // In the way of a walker stepping off the road, it does not stop for walkers on the sidewalk.
  bool gives_way = !road;
  for_near(i, 1, [&](uint32_t k) {
    if (gives_way && has_way(k) && in_way_of(w_[k].x, w_[k].y, w_[k].yaw, w.x, w.y) > 0) {
      gives_way = false;
    }
  });
  double lo[kMaxBlocks], hi[kMaxBlocks], lon_of[kMaxBlocks], along_of[kMaxBlocks];
  bool yield_to[kMaxBlocks];
  int n = 0;
  double follow = v;
  for_near(i, 1, [&](uint32_t k) {
    const Walker& o = w_[k];
    const double dx = o.x - w.x, dy = o.y - w.y;
    const double lon = dx * c + dy * sn, lat = dx * sn - dy * c;
    if (lon < -kBeside || lon > kAhead || std::abs(lat) > 2 * kClear) return;
    const double cy = std::cos(o.yaw - w.yaw);
    // One ahead going its way stepping back (out of a lane): it steps back with it.
    const double along = cy > kSameWay ? std::min(o.v, o.want) * cy : std::max(0.0, o.v * cy);
    if (cy > kSameWay && o.v >= kMoving && lon > 0) {  // going its way: followed
      follow = ru::pace_behind(w.x, w.y, w.yaw, o.x, o.y, o.yaw, o.v, follow, kFollowGap);
      if (lon > kBeside) return;
    }
    if (n == kMaxBlocks) return;
    lo[n] = r + lat - kClear;
    hi[n] = r + lat + kClear;
    lon_of[n] = lon;
    along_of[n] = along;
    yield_to[n] = gives_way || has_way(k);  // on the road it stops for no walker off it
    ++n;
  });
  auto free_at = [&](double x) {
    for (int b = 0; b < n; ++b) {
      if (x > lo[b] && x < hi[b]) return false;
    }
    return x >= lo_b - 1e-9 && x <= hi_b + 1e-9;
  };
  // Candidates: its keep-right, where it is, and every block's edges; the nearest its keep-right.
  target = NAN;
  auto consider = [&](double x) {
    x = std::clamp(x, lo_b, hi_b);
    if (!free_at(x)) return;
    if (std::isnan(target) || std::abs(x - r0) < std::abs(target - r0) - 1e-9 ||
        (std::abs(x - r0) < std::abs(target - r0) + 1e-9 &&
         std::abs(x - r) < std::abs(target - r))) {
      target = x;
    }
  };
  consider(r0);
  consider(r);
  for (int b = 0; b < n; ++b) {
    consider(lo[b] - 1e-3);
    consider(hi[b] + 1e-3);
  }
  if (!std::isnan(target)) return follow;
  target = r;  // no way past: it slows behind those in its way
  for (int b = 0; b < n; ++b) {
    if (yield_to[b] && lon_of[b] > 0 && r > lo[b] && r < hi[b] && lon_of[b] < kFollowGap + 0.3) {
      follow = std::min(follow, along_of[b]);
    }
  }
  return follow;
}

// On the road, or stepping off it (up to kOffRoad past it, where its trip ends): it has the way
// over the walkers on the sidewalk.
bool PoolWalkers::has_way(size_t i) const {
  const ru::WalkCrossing* c = current_crossing(i);
  return c && w_[i].arc > c->enter && w_[i].arc < c->exit + kOffRoad + 0.1;
}

// Whether its box at (x, y, yaw), grown by kMargin, is clear of every other walker's, or at least
// of each it overlaps now no nearer than it is now (a new trip's turn, a respawn: it walks off).
bool PoolWalkers::clear_at(size_t i, double x, double y, double yaw, uint32_t* who) const {
  const WalkerSpec& a = specs_[i];
  const Walker& w = w_[i];
  const bool off_road = !has_way(i);
  bool clear = true;
  for_near(i, 1, [&](uint32_t k) {
    if (!clear) return;
    const Walker& o = w_[k];
    if (off_road && has_way(k) && in_way_of(o.x, o.y, o.yaw, x, y) > 0 &&
        in_way_of(o.x, o.y, o.yaw, w.x, w.y) == 0) {
      clear = false;  // a walker on the road has the way: it does not step into it
      return;
    }
    if (std::abs(o.x - x) > 1.5 || std::abs(o.y - y) > 1.5) return;
    const WalkerSpec& b = specs_[k];
    if (!boxes_overlap(x, y, yaw, a.length + 2 * kMargin, a.width + 2 * kMargin, o.x, o.y, o.yaw,
                       b.length, b.width)) {
      return;
    }
    const bool was = boxes_overlap(w.x, w.y, w.yaw, a.length + 2 * kMargin, a.width + 2 * kMargin,
                                   o.x, o.y, o.yaw, b.length, b.width);
    if (!was || std::hypot(o.x - x, o.y - y) < std::hypot(o.x - w.x, o.y - w.y) - 1e-9) {
      clear = false;
      if (who) *who = k;
    }
  });
  return clear;
}

// Its step: `v` along its path and its sidestep towards `target` at kSideRate; failing that
// (a walker there), the sidestep alone, the step alone, or it stands.
// Whether walker i, blocked by walker k, gives way: k comes first in order, or stands still.
bool PoolWalkers::gives_way_to(size_t i, uint32_t k) const {
  return k != kNone && (k < i || w_[k].want <= 0);
}

void PoolWalkers::move(size_t i, double v, double target, double dt) {
  Walker& w = w_[i];
  w.want = v;
  const double side = kSideRate * dt;
  const double dodge = w.dodge + std::clamp(target - keep_right(i), -side, side);
  const double arc = std::clamp(w.arc + v * dt, 0.0, w.path.length());
  // Blocked by a walker before it in order (it has the way), off the road: it gives way, a
  // sidestep away from that one (up to kEscape off its path) or a step back.
  double away = 0;
  uint32_t by = kNone;
  if (const Placed p = placed(i, arc, dodge, std::abs(arc - w.arc));
      !clear_at(i, p.x, p.y, p.yaw, &by) && gives_way_to(i, by) && v > 0 && !has_way(i)) {
    const Walker& o = w_[by];
    away = (w.x - o.x) * std::sin(w.yaw) - (w.y - o.y) * std::cos(w.yaw) > 0 ? side : -side;
    if (std::abs(keep_right(i) + away) > kEscape) away = 0;
  }
  const double tries[5][2] = {{arc, dodge},
                              {w.arc, dodge},
                              {arc, w.dodge},
                              {w.arc, w.dodge + away},
                              {std::max(0.0, w.arc - 0.5 * v * dt), w.dodge}};
  const double arc0 = w.arc;
  const int n_tries = by != kNone && gives_way_to(i, by) && v > 0 && !has_way(i) ? 5 : 3;
  for (int n = 0; n < n_tries; ++n) {
    const auto& t = tries[n];
    const Placed p = placed(i, t[0], t[1], std::abs(t[0] - w.arc));
    if ((t[0] == w.arc && t[1] == w.dodge) || !clear_at(i, p.x, p.y, p.yaw)) continue;
    w.arc = t[0];
    w.dodge = t[1];
    w.ox = p.ox;
    w.oy = p.oy;
    w.x = p.x;
    w.y = p.y;
    w.yaw = p.yaw;
    break;
  }
  const double v_now = (w.arc - arc0) / dt;
  w.walked += std::abs(w.arc - arc0);
  w.acc = (v_now - w.v) / dt;
  w.v = v_now;
}

}  // namespace convoy::traffic_pool
