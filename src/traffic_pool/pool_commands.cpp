// Scenario commands for pooled road users (pool.h, set_commands; docs/road_users.md, "Pooled
// road users", Commands). Each command is read by src/road_users' parser, the one the agents
// use, so the pool takes exactly their contract; this file applies it to the pool's arrays
// (untimed trajectories and walkers' routes: pool_paths.cpp). A command holds for the next step.
#include <algorithm>
#include <cmath>

#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {

namespace ru = convoy::road_users;
using nlohmann::json;

namespace {
constexpr double kLocateRadius = 50;         // m: farther from every driving lane, it stands
constexpr double kLocateHeading = M_PI / 3;  // its yaw within 60 degrees of the lane's
constexpr double kRouteRadius = 20;          // m: a route position's lane (the parser's)
constexpr int kLaneSearch = 6;               // lanes to either side a lane command looks at
constexpr double kMinPace = 1e-3;  // m/s: a walker commanded to stand (its rules divide by it)
}  // namespace

void Pool::set_commands(const json& pack, const std::string& where, const std::string& prefix,
                        double ref_ahead) {
  if (!pack.is_object()) {
    throw PoolError(where + ": expected a JSON object {\"<road user id>\": command, ...}, got " +
                    ru::command_parts::shown(pack));
  }
  if (cmd_.size() != n_) {
    cmd_.assign(n_, std::nullopt);
    routed_.assign(n_, {});
    stand_.assign(n_, 0);
    polyline_.assign(n_, {});
    poly_path_.assign(n_, {});
  }
  cmd_ref_ahead_ = ref_ahead;
  if (walkers_ && wcmd_.size() != walkers_->size()) wcmd_.assign(walkers_->size(), std::nullopt);
  if (index_.empty()) {
    for (size_t i = 0; i < n_; ++i) index_.emplace(specs_[i].id, i);
    for (size_t k = 0; walkers_ && k < walkers_->size(); ++k)
      index_.emplace(walkers_->spec(k).id, n_ + k);
  }
  for (const auto& [key, value] : pack.items()) {
    std::string id = key;
    if (!prefix.empty() && id.rfind(prefix, 0) == 0 && !index_.count(id)) {
      id = id.substr(prefix.size());
    }
    const auto it = index_.find(id);
    if (it == index_.end()) {
      throw PoolError(where + ": no road user '" + key + "' in the pool (ids as it publishes " +
                      "them, with or without '" + prefix + "')");
    }
    const std::string name = where + ": road user '" + key + "'";
    try {
      if (it->second < n_) {
        cmd_[it->second] = ru::parse_vehicle_command(value, "command", net_.graph());
      } else {
        wcmd_[it->second - n_] = ru::parse_pedestrian_command(value, "command", net_.graph());
      }
    } catch (const ru::CommandError& e) {
      throw PoolError(name + ": " + e.what());
    }
  }
  has_commands_ = true;
}

// Before the vehicles move (after their IDM accelerations and MOBIL's changes): a speed command
// sets the acceleration that reaches its speed this step, a lane command changes lanes, a
// polyline drives it along (a route with it waits until it comes alone), a vehicle standing off
// the lanes stays (one whose polyline has stopped there stops).
void Pool::command_before_move(double dt) {
  for (size_t i = 0; i < n_; ++i) {
    if (!polyline_[i].empty() && !on_polyline(i)) {
      polyline_[i].clear();
      poly_path_[i] = {};
      if (stand_[i]) v_[i] = acc_[i] = 0;
    }
    if ((!present(i) && !stand_[i]) || !cmd_[i]) continue;
    const ru::VehicleCommand& c = *cmd_[i];
    if (c.polyline) {
      drive_polyline(i, c, dt);
      continue;
    }
    if (!present(i)) continue;
    if (c.route) command_route(i, *c.route);
    if (c.lane) command_lane(i, *c.lane);
    if (c.speed) acc_[i] = (c.speed->speed - v_[i]) / dt;
  }
}

// After they moved: the speed command's speed exactly and its acceleration published; a
// teleport or a timed trajectory puts it at its pose, a polyline's step where it has driven it
// (localised on the pool's lanes).
void Pool::command_after_move(double dt) {
  for (size_t i = 0; i < n_; ++i) {
    if ((!present(i) && !stand_[i]) || !cmd_[i]) continue;
    const ru::VehicleCommand& c = *cmd_[i];
    if (c.speed && present(i)) {
      v_[i] = c.speed->speed;
      if (c.speed->acceleration) acc_[i] = *c.speed->acceleration;
    }
    const std::optional<ru::CommandPose>& pose = c.teleport ? c.teleport : c.timed;
    if (pose) {
      const double v0 = v_[i];
      const double v = pose->speed.value_or(v0);
      put_at(i, *pose);
      v_[i] = stand_[i] ? 0.0 : v;
      acc_[i] = c.speed ? acc_[i] : (v_[i] - v0) / dt;
    }
    if (c.polyline) {  // its reference point, at the speed it drove
      const double back = cmd_ref_ahead_ * specs_[i].length;
      put_at(i, {x_[i] - back * std::cos(yaw_[i]), y_[i] - back * std::sin(yaw_[i]), yaw_[i],
                 std::nullopt});
    }
  }
  for (auto& c : cmd_) c.reset();
  // The walkers step next: a speed command's pace for that step.
  for (size_t k = 0; k < wcmd_.size(); ++k) {
    const auto& c = wcmd_[k];
    if (c && c->speed) pace_.emplace_back(k, walkers_->set_pace(k, std::max(*c->speed, kMinPace)));
  }
  command_walker_paths();
}

// After the walkers' step: their own pace again; a teleport or a timed trajectory puts the
// walker at its pose, from where it walks to the nearest sidewalk and on.
void Pool::command_walkers_after(double dt) {
  for (const auto& [k, own] : pace_) walkers_->set_pace(k, own);
  pace_.clear();
  for (size_t k = 0; k < wcmd_.size(); ++k) {
    if (!wcmd_[k]) continue;
    const ru::PedestrianCommand& c = *wcmd_[k];
    const std::optional<ru::CommandPose>& p = c.teleport ? c.teleport : c.timed;
    if (p) {
      const double v = p->speed.value_or(c.speed.value_or(walkers_->speed(k)));
      walkers_->put_at(k, p->x, p->y, p->yaw, v, dt);
    }
    wcmd_[k].reset();
  }
}

double PoolWalkers::set_pace(size_t i, double v) {
  const double own = specs_[i].speed;
  specs_[i].speed = v;
  return own;
}

void PoolWalkers::put_at(size_t i, double x, double y, double yaw, double v, double dt) {
  Walker& w = w_[i];
  w.acc = (v - w.v) / dt;
  w.v = v;
  w.x = x;
  w.y = y;
  w.yaw = yaw;
  walk_on(i, x, y, yaw, false);  // to the nearest sidewalk (50 m; none: it stands) and on
  const opendrive::Pose2 start = w.path.at(0);
  w.ox = x - start.x;
  w.oy = y - start.y;
  w.dodge = 0;
  place(i, 0);
  w.yaw = yaw;
}

// Its box's centre to the commanded reference point's pose; on the nearest pool lane whose
// heading is within 60 degrees of its yaw (50 m), or standing there when none is: then it is
// off the lanes (not present: no vehicle comes within 50 m of it) until it is put on them.
void Pool::put_at(size_t i, const ru::CommandPose& p) {
  const double half = 0.5 * specs_[i].length;
  const double cx = p.x + cmd_ref_ahead_ * specs_[i].length * std::cos(p.yaw);
  const double cy = p.y + cmd_ref_ahead_ * specs_[i].length * std::sin(p.yaw);
  const auto at = net_.graph().locate_if(
      cx, cy, p.yaw, kLocateRadius, [&](const opendrive::LaneNode& n, double heading) {
        return net_.pool_lane(n.index) != kNone &&
               std::abs(std::remainder(heading - p.yaw, 2 * M_PI)) <= kLocateHeading;
      });
  if (claim_[i] != kNone) --claims_[claim_[i]];
  claim_[i] = kNone;
  if (!at) {  // off the network (absent to the lanes and the grid), standing where it is put
    stand_[i] = 1;
    lane_[i] = prev_[i] = next_[i] = next2_[i] = kNone;
  } else {
    stand_[i] = 0;
    const uint32_t l = net_.pool_lane(at->lane);
    const PoolLane& lane = net_.lane(l);
    // Its centre's s: the nearest of the lane's poses (the pool's own geometry).
    size_t best = 0;
    double best_d = INFINITY;
    for (size_t k = 0; k < lane.poses.size(); ++k) {
      const double d = std::hypot(lane.poses[k].x - cx, lane.poses[k].y - cy);
      if (d < best_d) {
        best_d = d;
        best = k;
      }
    }
    lane_[i] = l;
    prev_[i] = kNone;
    s_[i] = std::min(best * lane.ds, lane.length) + half;
    if (lane.junction >= 0) {
      claim_[i] = l;
      ++claims_[l];
    }
    route_[i].clear();
    next_[i] = choose(i, l);
    next2_[i] = choose(i, next_[i]);
  }
  x_[i] = cx;
  y_[i] = cy;
  yaw_[i] = p.yaw;
}

// An immediate change to the adjacent lane towards the commanded one (road and lane id) when it
// is beside it (a MOBIL-style change, without the lateral blend); on it already, or not beside
// it (it has just left that road): it keeps its lane.
void Pool::command_lane(size_t i, const ru::VehicleCommand::Lane& want) {
  const uint32_t l = lane_[i];
  const PoolLane& cur = net_.lane(l);
  if (cur.road_id == want.road && cur.lane_id == want.lane) return;
  for (const bool left : {true, false}) {
    uint32_t k = l;
    for (int step = 0; step < kLaneSearch; ++step) {
      k = left ? net_.lane(k).left : net_.lane(k).right;
      if (k == kNone) break;
      if (net_.lane(k).road_id != want.road || net_.lane(k).lane_id != want.lane) continue;
      const uint32_t t = left ? cur.left : cur.right;
      if (claim_[i] != kNone) --claims_[claim_[i]];
      claim_[i] = kNone;
      changed_into_[t] = 1;
      s_[i] = s_[i] * net_.lane(t).length / cur.length;
      lane_[i] = t;
      prev_[i] = kNone;
      route_[i].clear();
      next_[i] = choose(i, t);
      next2_[i] = choose(i, next_[i]);
      ++stats_.lane_changes;
      return;
    }
  }
}

// Re-routes it through the positions (each on its nearest pool lane within 20 m) with the
// lane graph's routing, as a spec's `To` is; the same positions again do not re-plan.
void Pool::command_route(size_t i, const ru::Points& positions) {
  if (routed_[i] == positions) return;
  routed_[i] = positions;
  const opendrive::LaneGraph& g = net_.graph();
  opendrive::RouteOptions opt;
  opt.lane_changes = false;
  opendrive::LaneIndex from = net_.lane(lane_[i]).graph_lane;
  const opendrive::LaneNode& n0 = g.lane(from);
  double s_from = n0.forward ? n0.s0 + s_[i] : n0.s1 - s_[i];
  std::vector<uint32_t> lanes;  // in driving order, after its present lane
  for (const auto& p : positions) {
    const auto at = g.locate_if(
        p[0], p[1], std::nullopt, kRouteRadius,
        [&](const opendrive::LaneNode& n, double) { return net_.pool_lane(n.index) != kNone; });
    if (!at) break;
    const auto r = g.route(from, s_from, at->lane, at->s, opt);
    if (!r) {
      throw PoolError("road user '" + specs_[i].id + "': command.route: no path from road '" +
                      net_.lane(lane_[i]).road_id + "' to (" + std::to_string(p[0]) + ", " +
                      std::to_string(p[1]) + ")");
    }
    for (size_t k = 1; k < r->segments.size(); ++k) {
      const uint32_t pl = net_.pool_lane(r->segments[k].lane);
      if (pl != kNone) lanes.push_back(pl);
    }
    from = at->lane;
    s_from = at->s;
  }
  route_[i].assign(lanes.rbegin(), lanes.rend());
  mobil_[i] = 0;  // as with `To`: a lane change would leave the route
  if (claim_[i] != kNone && claim_[i] != lane_[i]) {
    --claims_[claim_[i]];
    claim_[i] = kNone;
  }
  next_[i] = choose(i, lane_[i]);
  next2_[i] = choose(i, next_[i]);
}

bool Pool::commanded_lateral(size_t i) const {
  return has_commands_ && cmd_[i] && (cmd_[i]->lane || cmd_[i]->route || cmd_[i]->polyline);
}

}  // namespace convoy::traffic_pool
