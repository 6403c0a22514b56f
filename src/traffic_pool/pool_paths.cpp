// Commanded paths for pooled road users (pool_commands.cpp; docs/road_users.md, "Pooled road
// users", Commands), by the agents' rules in src/road_users:
//   - a vehicle's untimed trajectory (polyline), as vehicle_behaviour.cpp drives one: pure
//     pursuit of its reference point along the polyline (straight on past its end) on the
//     kinematic bicycle, at the `speed` command's speed or IDM's behind the leader on the
//     polyline (no lights, no junctions); each step it is localised on the pool's lanes as a
//     teleport is (Pool::put_at), so the others follow it there and it drives on from there
//     when the command stops;
//   - a walker's route and polyline, as pedestrian_behaviour.cpp walks them
//     (road_users::walk_through, polyline_walk, step_along).
#include <algorithm>
#include <cmath>
#include <random>

#include "road_users/bicycle.h"
#include "road_users/neighbours.h"
#include "road_users/pure_pursuit.h"
#include "road_users/vehicle_behaviour.h"
#include "traffic_pool/draw.h"
#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {

namespace ru = convoy::road_users;

namespace {
constexpr double kWheelbase = 0.6;   // of its length (the agents' 2.7 m of 4.5 m)
constexpr double kLookRadius = 100;  // m: the road users it sees (the agents' Radius)
constexpr double kMaxDecel = 9;      // m/s^2 (the agents' MaxDeceleration, the pool's)
constexpr double kFollowGap = 1.0;   // m: a walker closer than this behind one keeps its pace
}  // namespace

bool Pool::on_polyline(size_t i) const { return has_commands_ && cmd_[i] && cmd_[i]->polyline; }

// IDM towards v0 behind the nearest road user ahead on `path` (road_users::leader_on: within
// its width + 1 m of the polyline, its front ahead of this one's), bounded by its braking limit.
double Pool::polyline_accel(size_t i, const ru::Path& path, double v0) {
  const VehicleSpec& sp = specs_[i];
  const double back = cmd_ref_ahead_ * sp.length;
  const double rx = x_[i] - back * std::cos(yaw_[i]), ry = y_[i] - back * std::sin(yaw_[i]);
  ru::Neighbours around;  // box centres: length_offset 0
  for_near(rx, ry, kLookRadius, [&](uint32_t k) {
    if (k == i) return;
    ru::Neighbour u;
    u.x = x_[k];
    u.y = y_[k];
    u.yaw = yaw_[k];
    u.speed = v_[k];
    u.length = specs_[k].length;
    u.width = specs_[k].width;
    around.push_back(u);
  });
  const ru::Path::Proj pr = path.project(rx, ry);
  const double front = pr.arc + back + 0.5 * sp.length;
  const ru::Observer me{sp.id, rx, ry, yaw_[i], v_[i], kLookRadius};
  const ru::LaneNeighbour lead =
      ru::leader_on(path, pr.index, front, ru::kVehicleSampleDs, me, around);
  return std::clamp(sp.idm.accel(v_[i], lead.gap, lead.speed, v0), -kMaxDecel, sp.idm.a);
}

// One step along c.polyline: its speed and acceleration (the `speed` command's, else IDM's),
// its box moved (its reference point by the bicycle, steered by pure pursuit); command_after_move
// localises it there.
void Pool::drive_polyline(size_t i, const ru::VehicleCommand& c, double dt) {
  const VehicleSpec& sp = specs_[i];
  const double back = cmd_ref_ahead_ * sp.length;
  const ru::PlanarPose ref{x_[i] - back * std::cos(yaw_[i]), y_[i] - back * std::sin(yaw_[i]),
                           yaw_[i]};
  if (polyline_[i] != *c.polyline) {
    polyline_[i] = *c.polyline;
    poly_path_[i] = ru::polyline_path(*c.polyline, ru::kVehicleSampleDs, ref.x, ref.y);
  }
  const ru::Path& path = poly_path_[i];
  double v = 0, acc = 0;
  if (c.speed) {
    v = c.speed->speed;
    acc = c.speed->acceleration.value_or((v - v_[i]) / dt);
  } else {
    const double v0 = present(i) ? std::min(sp.idm.v0, net_.lane(lane_[i]).limit) : sp.idm.v0;
    acc = polyline_accel(i, path, v0);
    v = v_[i] + acc * dt;
    if (v < 0) {
      v = 0;
      acc = -v_[i] / dt;
    }
  }
  const ru::KinematicBicycle bicycle{kWheelbase * sp.length};
  const double arc = path.project(ref.x, ref.y).arc;
  const double steer = ru::pursue(ru::PurePursuit{}, bicycle, path, arc, ref, v_[i], true);
  const ru::BicycleMotion moved = ru::step_bicycle(bicycle, ref, v, steer, dt);
  v_[i] = v;
  acc_[i] = acc;
  yaw_[i] = moved.pose.yaw;
  x_[i] = moved.pose.x + back * std::cos(yaw_[i]);
  y_[i] = moved.pose.y + back * std::sin(yaw_[i]);
}

// Before the walkers step: a route re-plans its walk, a polyline is followed this step (not
// with a teleport or a timed trajectory, which put it somewhere this step).
void Pool::command_walker_paths() {
  for (size_t k = 0; k < wcmd_.size(); ++k) {
    const auto& c = wcmd_[k];
    if (!c || c->teleport || c->timed) continue;
    if (c->route) walkers_->walk_route(k, *c->route);
    if (c->polyline) walkers_->follow_polyline(k, *c->polyline, c->speed.has_value());
  }
}

void PoolWalkers::walk_route(size_t i, const ru::Points& via) {
  Commanded& c = commanded_[i];
  if (c.route == via) return;
  c.route = via;
  c.polyline.clear();  // (a polyline this step follows it; without, it walks the route)
  Walker& w = w_[i];
  w.rng = mix(w.rng);
  std::mt19937_64 rng(w.rng);
  ru::WalkPath path;
  ru::walk_through(net_.graph(), path, w.x, w.y, w.yaw, via, std::nullopt, rng);
  w.path = std::move(path);
  w.arc = 0;
  w.last_crosswalk = -1;
  // Already on the road where it starts: it is crossing, it does not wait at a curb.
  const auto& crossings = w.path.road_crossings;
  w.committed = !crossings.empty() && crossings[0].enter - ru::kCurbWait <= 1e-9 ? 0 : SIZE_MAX;
  w.ox = w.oy = w.dodge = 0;  // its path starts where it stands
  place(i, 0);
}

void PoolWalkers::follow_polyline(size_t i, const ru::Points& points, bool paced) {
  Commanded& c = commanded_[i];
  if (c.polyline != points) {
    c.polyline = points;
    c.walk = ru::polyline_walk(points, w_[i].yaw);
  }
  c.now = true;
  c.paced = paced;
}

bool PoolWalkers::on_polyline(size_t i) const {
  const auto it = commanded_.find(i);
  return it != commanded_.end() && !it->second.polyline.empty();
}

// Along its polyline this step (at its pace, not past a walker ahead in its way unless the pace
// is commanded); the step after the last one, it walks from where it stands to the nearest
// sidewalk and on (as after a teleport).
bool PoolWalkers::step_commanded(size_t i, double dt) {
  const auto it = commanded_.find(i);
  if (it == commanded_.end()) return false;
  Commanded& c = it->second;
  Walker& w = w_[i];
  if (!c.now) {
    if (!c.polyline.empty()) {
      c.polyline.clear();
      c.walk = {};
      put_at(i, w.x, w.y, w.yaw, w.v, dt);
    }
    if (c.route.empty()) commanded_.erase(it);
    return false;
  }
  c.now = false;
  double v = specs_[i].speed;
  if (!c.paced) {
    for_near(i, 1, [&](uint32_t k) {
      v = ru::pace_behind(w.x, w.y, w.yaw, w_[k].x, w_[k].y, w_[k].yaw, w_[k].v, v, kFollowGap);
    });
  }
  const ru::WalkStep m = ru::step_along(c.walk, w.x, w.y, w.yaw, v, dt);
  w.acc = (m.moved / dt - w.v) / dt;
  w.v = m.moved / dt;
  w.want = v;
  w.walked += m.moved;
  w.x = m.x;
  w.y = m.y;
  w.yaw = m.yaw;
  w.committed = SIZE_MAX;  // off its path: no crossing of it is under way
  return true;
}

}  // namespace convoy::traffic_pool
