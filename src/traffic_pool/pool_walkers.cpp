// Pooled walkers' step (pool_walkers.h): along its path at its pace, behind the walkers in its
// way, waiting at the curb and crossing by road_users' rules, the next trip at its path's end.
#include "traffic_pool/pool_walkers.h"

#include <algorithm>
#include <cmath>

#include "road_users/pedestrian_behaviour.h"

namespace convoy::traffic_pool {

namespace odr = convoy::opendrive;
namespace ru = convoy::road_users;

namespace {
constexpr double kCell = 5;           // m: the walkers' grid
constexpr double kThreatRadius = 70;  // m around a crossing: vehicles that may threaten it
constexpr double kKeepOff = 8;        // m: no moving vehicle this near when it steps on
constexpr double kEaseRate = 0.5;     // m its offset from its path turns per m walked
constexpr double kBodyMargin = 0.3;   // m kept between its body and a vehicle's front
const ru::CrossingCaution kCaution{8, 4};

// Distance from vehicle v's box to the segment a-b when the segment's nearest point is not
// behind its back (it comes towards it, or is beside it), else infinity.
double approaching(const ru::CrossingVehicle& v, const odr::Pose2& a, const odr::Pose2& b) {
  const double ex = b.x - a.x, ey = b.y - a.y, len2 = ex * ex + ey * ey;
  const double f =
      len2 > 1e-12 ? std::clamp(((v.x - a.x) * ex + (v.y - a.y) * ey) / len2, 0.0, 1.0) : 0.0;
  const double px = a.x + f * ex - v.x, py = a.y + f * ey - v.y;
  if (px * std::cos(v.yaw) + py * std::sin(v.yaw) < -0.5 * v.length) return INFINITY;
  return std::hypot(px, py) - 0.5 * v.length;
}
}  // namespace

double PoolWalkers::walk_phase(size_t i) const {
  return std::fmod(w_[i].walked / specs_[i].stride, 1.0);
}

const ru::WalkCrossing* PoolWalkers::current_crossing(size_t i) const {
  const Walker& w = w_[i];
  for (const ru::WalkCrossing& c : w.path.road_crossings) {
    if (w.arc >= c.start - 1e-9 && w.arc <= c.end + 1e-9) return &c;
  }
  return nullptr;
}

bool PoolWalkers::crossing(size_t i) const { return current_crossing(i) != nullptr; }

bool PoolWalkers::on_road(size_t i) const {
  const ru::WalkCrossing* c = current_crossing(i);
  return c && w_[i].arc > c->enter && w_[i].arc < c->exit;
}

bool PoolWalkers::crossing_box(size_t i, Box& box) const {
  const Walker& w = w_[i];
  if (!commanded_.empty() && on_polyline(i)) {  // off its path: its body, wherever it walks
    box = {w.x, w.y, w.yaw, specs_[i].length + 2 * kBodyMargin, specs_[i].width + 2 * kBodyMargin};
    return true;
  }
  if (w.committed >= w.path.road_crossings.size()) return false;
  const ru::WalkCrossing& c = w.path.road_crossings[w.committed];
  if (w.arc >= c.exit) return false;
  const odr::Pose2 a = w.path.at(c.enter), b = w.path.at(c.exit);
  box.x = 0.5 * (a.x + b.x);
  box.y = 0.5 * (a.y + b.y);
  box.yaw = std::atan2(b.y - a.y, b.x - a.x);
  box.length = std::hypot(b.x - a.x, b.y - a.y) + 2 * kBodyMargin;
  box.width = 2 * (ru::kKeepRight + 0.5 * specs_[i].width + kBodyMargin);
  return true;
}

// How far right of its path's centre it is now.
double PoolWalkers::keep_right(size_t i) const {
  const Walker& w = w_[i];
  const double h = w.path.at(w.arc).heading;
  return w.ox * std::sin(h) - w.oy * std::cos(h) + w.dodge;
}

// Its pose at `arc`, kKeepRight right of the path and `dodge` further: its offset from the path
// turns towards kKeepRight by kEaseRate m per m it has `moved` (a new trip's path does not make
// it jump).
PoolWalkers::Placed PoolWalkers::placed(size_t i, double arc, double dodge, double moved) const {
  const Walker& w = w_[i];
  const odr::Pose2 p = w.path.at(arc);
  const double sn = std::sin(p.heading), cs = std::cos(p.heading);
  const double tx = ru::kKeepRight * sn, ty = -ru::kKeepRight * cs;
  const double dx = tx - w.ox, dy = ty - w.oy, d = std::hypot(dx, dy), turn = kEaseRate * moved;
  const double f = d > turn ? turn / d : 1.0;
  Placed out;
  out.ox = w.ox + f * dx;
  out.oy = w.oy + f * dy;
  out.x = p.x + out.ox + dodge * sn;
  out.y = p.y + out.oy - dodge * cs;
  out.yaw = w.path.poses.size() > 1 ? p.heading : w.yaw;
  return out;
}

void PoolWalkers::place(size_t i, double moved) {
  Walker& w = w_[i];
  const Placed p = placed(i, w.arc, w.dodge, moved);
  w.ox = p.ox;
  w.oy = p.oy;
  w.x = p.x;
  w.y = p.y;
  w.yaw = p.yaw;
}

void PoolWalkers::index_walkers() {
  if (head_.empty()) {
    min_x_ = net_.min_x - 60;
    min_y_ = net_.min_y - 60;
    gx_ = std::max(1, static_cast<int>((net_.max_x - min_x_ + 60) / kCell) + 1);
    gy_ = std::max(1, static_cast<int>((net_.max_y - min_y_ + 60) / kCell) + 1);
  }
  head_.assign(static_cast<size_t>(gx_) * gy_, kNone);
  chain_.assign(w_.size(), kNone);
  for (uint32_t i = 0; i < w_.size(); ++i) {
    const int cx = std::clamp(static_cast<int>((w_[i].x - min_x_) / kCell), 0, gx_ - 1);
    const int cy = std::clamp(static_cast<int>((w_[i].y - min_y_) / kCell), 0, gy_ - 1);
    const size_t c = static_cast<size_t>(cy) * gx_ + cx;
    chain_[i] = head_[c];
    head_[c] = i;
  }
}

// The vehicles crossing the line it walks on c (road_users::crossing_threat: the leg kept
// right as it walks it, each vehicle's box longer by its body's width and a margin, so that one
// whose front is "before the line" is before its body), and the distance from the nearest
// moving one's box to the part of the line on the road (not one going away from it).
std::vector<ru::CrossingThreat> PoolWalkers::threats(size_t i, const ru::WalkCrossing& c,
                                                     const VehiclesNear& vehicles,
                                                     double* nearest_moving) const {
  const ru::WalkPath& path = w_[i].path;
  const odr::Pose2 a = path.at(c.start), b = path.at(c.end);
  const double ex = b.x - a.x, ey = b.y - a.y, len = std::hypot(ex, ey);
  std::vector<ru::CrossingThreat> out;
  if (len < 1e-6) return out;
  std::vector<ru::CrossingVehicle> near;
  vehicles(0.5 * (a.x + b.x), 0.5 * (a.y + b.y), kThreatRadius, near);
  const double ux = ex / len, uy = ey / len, kr = keep_right(i);
  const ru::CrossingLeg leg{a.x + kr * uy, a.y - kr * ux, ux, uy, len};
  const double body = specs_[i].width + 2 * kBodyMargin;
  const odr::Pose2 ra = path.at(c.enter), rb = path.at(c.exit);
  for (ru::CrossingVehicle v : near) {
    v.length += body;
    if (const auto t = ru::crossing_threat(leg, v)) out.push_back(*t);
    if (nearest_moving && v.speed > 0.5) {
      *nearest_moving = std::min(*nearest_moving, approaching(v, ra, rb));
    }
  }
  return out;
}

// At the curb: the lights (the crossed road's approach red now and until it has crossed), then
// the gap, and no moving vehicle within kKeepOff m.
bool PoolWalkers::may_step_on(size_t i, const ru::WalkCrossing& c, double t,
                              const VehiclesNear& vehicles) {
  const Walker& w = w_[i];
  if (specs_[i].obey_lights && w.last_crosswalk >= 0 && !c.crosswalk.empty()) {
    const CrosswalkInfo& cw = crosswalks_[w.last_crosswalk];
    if (lights_) {
      for (uint32_t l : cw.lit) {
        const road_users::Light now = (*lights_)[l];
        if (now != road_users::Light::kRed && now != road_users::Light::kOff) return false;
      }
    } else if (cw.group >= 0 && cw.junction >= 0) {
      const double need = (c.exit - w.arc) / specs_[i].speed + 1.0;
      const double offset = net_.junctions()[cw.junction].offset_s;
      for (double when : {t, t + need}) {
        if (net_.cycle().state(when, offset, cw.group) != road_users::Light::kRed) return false;
      }
    }
  }
  double nearest = INFINITY;
  const auto th = threats(i, c, vehicles, &nearest);
  return nearest > kKeepOff && ru::gap_accepted(th, specs_[i].gap);
}

void PoolWalkers::step_walker(size_t i, double dt, double t, const VehiclesNear& vehicles) {
  Walker& w = w_[i];
  const double v_des = specs_[i].speed;
  const size_t was = w.committed;
  const double limit = ru::path_limit(
      w.path, w.arc, v_des, dt, w.committed, kCaution,
      [&](const ru::WalkCrossing& c) { return may_step_on(i, c, t, vehicles); },
      [&](const ru::WalkCrossing& c) { return threats(i, c, vehicles); });
  if (w.committed != was && w.committed != SIZE_MAX) ++stats_.crossings;
  double target = 0;
  double v = 0;
  if (limit < w.arc - 1e-9) {
    v = -std::min(v_des, (w.arc - limit) / dt);  // stepping back
    avoid(i, 0, target);
  } else {
    v = avoid(i, std::min(v_des, (limit - w.arc) / dt), target);
  }
  move(i, v, target, dt);
  // The trip's end (its path's, or kOffRoad past the road when its crossing ends the path: it
  // does not walk across the sidewalk's walkers to its centre): the next from the sidewalk here,
  // its offset from that path where it stands (eased off as it walks).
  const bool crossed = w.committed < w.path.road_crossings.size() &&
                       w.arc >= w.path.road_crossings[w.committed].exit + kOffRoad &&
                       w.path.road_crossings[w.committed].end >= w.path.length() - 1e-6;
  if (crossed || w.arc >= w.path.length() - 1e-6) {
    const double x = w.x, y = w.y;
    const auto at = ru::nearest_sidewalk(net_.graph(), x, y);
    if (at) {
      plan_trip(i, {at->lane, at->s});
    } else {
      walk_on(i, x, y, w.yaw);
    }
    const odr::Pose2 start = w.path.at(0);  // (w.x, w.y: a respawn's spot)
    w.ox = w.x - start.x;
    w.oy = w.y - start.y;
    w.dodge = 0;
    place(i, 0);
  }
}

std::vector<std::pair<uint32_t, uint32_t>> PoolWalkers::overlaps() const {
  std::vector<std::pair<uint32_t, uint32_t>> out;
  for (uint32_t i = 0; i < w_.size(); ++i) {
    for_near(i, 1, [&](uint32_t k) {
      const WalkerSpec &a = specs_[i], &b = specs_[k];
      if (k > i && boxes_overlap(w_[i].x, w_[i].y, w_[i].yaw, a.length, a.width, w_[k].x, w_[k].y,
                                 w_[k].yaw, b.length, b.width)) {
        out.emplace_back(i, k);
      }
    });
  }
  std::sort(out.begin(), out.end());
  return out;
}

void PoolWalkers::step(double dt, double t, const VehiclesNear& vehicles,
                       const std::vector<road_users::Light>* lane_lights) {
  lights_ = lane_lights;
  index_walkers();
  for (size_t i = 0; i < w_.size(); ++i) {
    if (!commanded_.empty() && step_commanded(i, dt)) continue;
    step_walker(i, dt, t, vehicles);
  }
}

}  // namespace convoy::traffic_pool
