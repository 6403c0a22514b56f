// A road vehicle's manoeuvres (vehicle_behaviour.h): MOBIL lane changes onto a route keeping
// the target lane, re-planning from where it stands, and the commands' route, lane change and
// polyline.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "road_users/vehicle_behaviour.h"
#include "road_users/vehicle_stepper.h"

namespace convoy::road_users {
namespace odr = convoy::opendrive;

namespace {
constexpr double kHeadingTolerance = 60.0 * M_PI / 180.0;  // localising: lane direction vs yaw
}  // namespace

std::optional<odr::LanePosition> locate_drivable(const odr::LaneGraph& graph, double x, double y,
                                                 double yaw, double max_distance) {
  // A driving lane whose direction is within kHeadingTolerance of yaw; else any driving lane
  // (it turns towards it).
  auto loc = graph.locate_if(x, y, yaw, max_distance, [&](const odr::LaneNode& n, double h) {
    return n.drivable() && std::abs(std::remainder(h - yaw, 2 * M_PI)) <= kHeadingTolerance;
  });
  if (loc) return loc;
  return graph.locate_if(x, y, yaw, max_distance,
                         [](const odr::LaneNode& n, double) { return n.drivable(); });
}

namespace vehicle_detail {

void Stepper::consider_lane_change() {
  // MOBIL, in the local frame at the agent: neighbours by longitudinal (along my heading)
  // and lateral offset, each lane a band around its centre.
  const auto loc = d.graph->locate(s.x, s.y, s.yaw);
  if (!loc || loc->lane == odr::kNoLane) return;
  const odr::LaneNode& lane = d.graph->lane(loc->lane);
  if (lane.junction != "-1") return;
  const VehicleSnapshot* snap = perceived();
  const Neighbours none;
  const Neighbours& around = snap && snap->neighbours ? *snap->neighbours : none;
  const Observer me = observer();
  const double c = std::cos(s.yaw), sn = std::sin(s.yaw);
  const double my_front = d.front_offset();
  const double my_rear = -d.rear_overhang;
  const double v0 = desired_speed();
  const bool open_before = s.open_end;  // (planning a change that is not taken sets it)
  for (int side : {+1, -1}) {
    const odr::LaneIndex target = side > 0 ? lane.left() : lane.right();
    const bool allowed = side > 0 ? lane.change_left() : lane.change_right();
    if (target == odr::kNoLane || !allowed || !d.graph->lane(target).drivable()) continue;
    const odr::LaneNode& tl = d.graph->lane(target);
    // Lateral offset of the target lane's centre in my frame.
    const odr::WorldPose wc = d.graph->world_pose(lane.road->id, lane.lane_id, loc->s);
    const odr::WorldPose wt = d.graph->world_pose(tl.road->id, tl.lane_id, loc->s);
    const double centre = -(wt.x - s.x) * sn + (wt.y - s.y) * c;
    const double own = -(wc.x - s.x) * sn + (wc.y - s.y) * c;
    const double w = std::abs(centre - own);
    if (w < 1.0) continue;
    const LaneNeighbours here = lane_neighbours(me, around, own, 0.5 * w, my_front, my_rear);
    const LaneNeighbours there = lane_neighbours(me, around, centre, 0.5 * w, my_front, my_rear);
    const MobilDecision dec =
        decide_lane_change(s.driving.idm, d.mobil, s.v, v0, d.length, here, there);
    if (dec.outcome != LaneChange::kChange) continue;
    // The route on from the target lane: keep that lane to the destination road if it can,
    // else any route there.
    const std::optional<odr::LaneRoute> route =
        route_keeping(target, loc->s, tl.lane_id - lane.lane_id);
    if (!route || route->segments.empty()) continue;
    Path p = make_path(*route);
    if (p.poses.size() < 2) continue;
    s.path = std::move(p);
    const auto pr = s.path.project(s.x, s.y);
    s.cursor = pr.index;
    s.arc = pr.arc;
    compute_goal_arcs();
    s.changing = side;
    return;
  }
  s.open_end = open_before;
}

void Stepper::set_path(const odr::LaneRoute& route) {
  s.path = make_path(route);
  const auto pr = s.path.project(s.x, s.y);
  s.cursor = pr.index;
  s.arc = pr.arc;
  compute_goal_arcs();
  s.changing = 0;
}

bool Stepper::relocalise() {
  const auto loc = locate_drivable(*d.graph, s.x, s.y, s.yaw, 50.0);
  if (!loc) {
    char where[96];
    std::snprintf(where, sizeof where, "(%.2f, %.2f)", s.x, s.y);
    warn_once("lost", std::string("no driving lane within 50 m of ") + where +
                          " after a command: it stops there");
    s.lost = true;
    s.next_look_ns = s.time_ns + 1000000000;
    return false;
  }
  s.lost = false;
  set_path(plan_from(loc->lane, loc->s));
  return true;
}

void Stepper::apply_route(const Points& positions) {
  const auto here = locate_drivable(*d.graph, s.x, s.y, s.yaw, 50.0);
  if (!here) fail(d.command_key + ".route", "the agent is not within 50 m of a driving lane");
  std::vector<Goal> goals;
  std::vector<size_t> index;
  for (size_t i = 0; i < positions.size(); ++i) {
    const auto [px, py] = positions[i];
    const auto loc = d.graph->locate_if(
        px, py, std::nullopt, 20.0, [](const odr::LaneNode& n, double) { return n.drivable(); });
    if (!loc) continue;  // checked when it arrived
    // A point at the agent, or behind it on its own lane, is passed already.
    if (std::hypot(px - s.x, py - s.y) < 3.0) continue;
    if (goals.empty() && loc->lane == here->lane) {
      const bool fwd = d.graph->lane(here->lane).forward;
      if (fwd ? loc->s <= here->s + 1.0 : loc->s >= here->s - 1.0) continue;
    }
    goals.push_back({loc->lane, loc->s});
    index.push_back(i);
  }
  s.goals = goals;
  s.onward = true;
  size_t failed = 0;
  auto route = route_from(here->lane, here->s, 0, &failed);
  if (!route) {
    const auto [px, py] = positions[index[failed]];
    const odr::LaneNode& n = d.graph->lane(s.goals[failed].lane);
    char what[200];
    std::snprintf(what, sizeof what, "no route on the lane graph to (%.2f, %.2f) (lane %s:%d)", px,
                  py, n.road->id.c_str(), n.lane_id);
    fail(d.command_key + ".route.positions[" + std::to_string(index[failed]) + "]", what);
  }
  set_path(*route);
  s.lane_run = {};
}

void Stepper::begin_lane(const VehicleCommand::Lane& c) {
  const bool same = s.lane_run.active && s.lane_run.road == c.road && s.lane_run.lane == c.lane &&
                    s.lane_run.from_lane == c.from_lane && c.progress >= s.lane_run.progress - 1e-9;
  if (same) {
    s.lane_run.progress = c.progress;
    return;
  }
  const std::string key = d.command_key + ".lane";
  const auto loc = locate_drivable(*d.graph, s.x, s.y, s.yaw, 50.0);
  if (!loc) fail(key, "the agent is not within 50 m of a driving lane");
  std::string road = c.road;
  int lane = c.lane, from = c.from_lane;
  if (loc->road_id != c.road) {
    // Not on that road (it has just left it, say): the same change relative to its lane.
    warn_once("lane-road", key + ".road: the agent is on road " + loc->road_id + ", not " + c.road +
                               ": lanes taken relative to its own");
    // Lanes between (ids, lane 0 skipped), applied to its own lane.
    int steps = c.lane - c.from_lane;
    if ((c.lane > 0) != (c.from_lane > 0)) steps -= steps > 0 ? 1 : -1;
    road = loc->road_id;
    from = loc->lane_id;
    lane = from;
    for (int k = 0; k < std::abs(steps); ++k) {
      lane += steps > 0 ? 1 : -1;
      if (lane == 0) lane += steps > 0 ? 1 : -1;
    }
  }
  const odr::LaneIndex tgt = d.graph->find(road, lane, loc->s);
  const odr::LaneIndex frm = d.graph->find(road, from, loc->s);
  char at[48];
  std::snprintf(at, sizeof at, " at s = %.1f", loc->s);
  if (tgt == odr::kNoLane)
    fail(key + ".lane", "road " + road + " has no lane " + std::to_string(lane) + at);
  if (frm == odr::kNoLane)
    fail(key + ".from_lane", "road " + road + " has no lane " + std::to_string(from) + at);
  if (!d.graph->lane(tgt).drivable())
    fail(key + ".lane", "lane " + road + ":" + std::to_string(lane) + " is a " +
                            d.graph->lane(tgt).type + " lane, not a driving lane");
  const odr::WorldPose wt = d.graph->world_pose(road, lane, loc->s);
  const odr::WorldPose wf = d.graph->world_pose(road, from, loc->s);
  const double h = wt.heading;
  s.lane_run.active = true;
  s.lane_run.road = c.road;
  s.lane_run.lane = c.lane;
  s.lane_run.from_lane = c.from_lane;
  s.lane_run.progress = c.progress;
  s.lane_run.d_from = -(wf.x - wt.x) * std::sin(h) + (wf.y - wt.y) * std::cos(h);
  // The route on from the target lane: keeping it to its next goal's road if it can, else
  // through its goals, else onward.
  auto route = route_keeping(tgt, loc->s, lane - from);
  set_path(route && !route->segments.empty() ? *route : plan_from(tgt, loc->s));
  s.lane_run.lateral = s.path.project(s.x, s.y).lateral;
  s.lane_run.e0 = s.lane_run.lateral - s.lane_run.d_from;
  s.lane_run.side = s.lane_run.d_from + s.lane_run.e0 < -0.5  ? 1
                    : s.lane_run.d_from + s.lane_run.e0 > 0.5 ? -1
                                                              : 0;
}

void Stepper::set_polyline(const Points& points) {
  if (points == s.polyline) return;
  s.polyline = points;
  s.traj_path = polyline_path(points, kVehicleSampleDs, s.x, s.y);
}

void Stepper::extend() {
  bool open = false;
  const odr::LaneRoute route = extended(plan(), s.path, s.arc, &open);
  s.open_end = open;
  s.path = make_path(route);
  const auto pr = s.path.project(s.x, s.y);
  s.cursor = pr.index;
  s.arc = pr.arc;
  compute_goal_arcs();
}

}  // namespace vehicle_detail
}  // namespace convoy::road_users
