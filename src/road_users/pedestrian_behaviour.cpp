// A pedestrian's step (pedestrian_behaviour.h).
#include "road_users/pedestrian_behaviour.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "road_users/walker.h"

namespace convoy::road_users {
namespace odr = convoy::opendrive;

namespace {

constexpr double kFollowGap = 1.0;  // m: closer than this behind a walker, it keeps its pace

struct Stepper {
  const PedestrianDescription& d;
  PedestrianState& s;

  void warn_once(const std::string& key, const std::string& text) {
    s.warnings.emplace_back(key, text);
  }
  bool step(int64_t duration_ns);
  bool respawn();
  void place(const PedestrianCommand& cmd, double dt);
  void walk_polyline(const PedestrianCommand& cmd, double v_des, double dt);
  double crossing_limit_now(double v_des, double dt);
  void walk_path(const std::optional<PedestrianCommand>& cmd, double v_des, double dt);
  void arrive();
  bool lights_allow(const WalkCrossing& c);
  std::vector<CrossingThreat> threats(const WalkCrossing& c) const;
  double walker_ahead_speed(double v) const;
  void replan(const Points& via);  // from where it stands, through `via`, then onward
  void set_polyline(const Points& points);
};

}  // namespace

PedestrianState start_pedestrian(const PedestrianDescription& d) {
  PedestrianState s;
  s.path = d.initial_path;
  s.idle = d.initial_idle;
  s.rng = d.initial_rng;
  s.kr = d.start_pose ? 0.0 : kKeepRight;
  s.kr_from = d.initial_kr_from;
  const odr::Pose2 p = s.path.at(0);
  s.x = p.x + s.kr * std::sin(p.heading);
  s.y = p.y - s.kr * std::cos(p.heading);
  s.yaw = d.start_pose ? d.start_pose->heading : p.heading;
  return s;
}

bool step_pedestrian(const PedestrianDescription& d, PedestrianState& s, int64_t duration_ns) {
  return Stepper{d, s}.step(duration_ns);
}

double rain_factor(double precipitation, bool rain) {
  return rain && precipitation > 0 ? 1.0 + 0.2 * std::clamp(precipitation, 0.0, 1.0) : 1.0;
}

namespace {

bool Stepper::step(int64_t duration_ns) {
  const double dt = duration_ns * 1e-9;
  s.time_ns += duration_ns;
  std::optional<PedestrianCommand> cmd;
  cmd.swap(s.command);
  if (s.absent && !(cmd && (cmd->teleport || cmd->timed))) return respawn();
  s.absent = false;
  if (cmd && (cmd->teleport || cmd->timed)) {
    place(*cmd, dt);
    return true;
  }
  if (cmd && cmd->route && *cmd->route != s.last_route) {
    s.last_route = *cmd->route;
    if (!cmd->polyline) s.off_path = false;
    replan(*cmd->route);
  }
  const bool on_poly = cmd && cmd->polyline;
  if (on_poly) {
    set_polyline(*cmd->polyline);
    s.off_path = true;
  } else if (s.off_path) {
    s.off_path = false;
    s.polyline.clear();
    replan({});
  }
  const double v_des = cmd && cmd->speed ? *cmd->speed : d.speed * s.rain_factor;
  if (on_poly) {
    walk_polyline(*cmd, v_des, dt);
  } else {
    walk_path(cmd, v_des, dt);
  }
  return true;
}

// Respawn: at its start again, once RespawnDelay has passed and no walker is within 1 m.
bool Stepper::respawn() {
  if (!d.respawn || s.time_ns - s.absent_since_ns < std::llround(d.respawn_delay_s * 1e9))
    return false;
  const odr::Pose2 p0 = d.initial_path.at(0);
  const double kr0 = d.start_pose ? 0.0 : kKeepRight;
  const double sx = p0.x + kr0 * std::sin(p0.heading);
  const double sy = p0.y - kr0 * std::cos(p0.heading);
  if (s.neighbours) {
    for (const Neighbours* group : {&s.neighbours->walkers, &s.neighbours->vehicles}) {
      for (const Neighbour& u : *group) {
        if (std::hypot(u.x - sx, u.y - sy) < 1.0) return false;
      }
    }
  }
  s.path = d.initial_path;
  s.idle = d.initial_idle;
  s.kr = kr0;
  s.kr_from = d.initial_kr_from;
  s.stand_at_end = false;
  s.arc = 0;
  s.v = s.acc = s.yaw_rate = 0;
  s.x = sx;
  s.y = sy;
  s.yaw = d.start_pose ? d.start_pose->heading : p0.heading;
  s.committed = SIZE_MAX;
  s.absent = false;
  return true;
}

void Stepper::place(const PedestrianCommand& cmd, double dt) {
  if (cmd.teleport) {
    // Put there once, then back to its routing from there.
    const PedestrianCommand::Pose& p = *cmd.teleport;
    s.x = p.x;
    s.y = p.y;
    s.yaw = std::remainder(p.yaw, 2 * M_PI);
    if (p.speed) s.v = *p.speed;
    s.acc = s.yaw_rate = 0;
    s.off_path = false;
    s.polyline.clear();
    replan({});
    return;
  }
  const PedestrianCommand::Pose& p = *cmd.timed;
  const double v = p.speed.value_or(0.0);
  const double yaw = std::remainder(p.yaw, 2 * M_PI);
  s.walked += std::hypot(p.x - s.x, p.y - s.y);
  s.yaw_rate = std::remainder(yaw - s.yaw, 2 * M_PI) / dt;
  s.acc = (v - s.v) / dt;
  s.x = p.x;
  s.y = p.y;
  s.yaw = yaw;
  s.v = v;
  s.off_path = true;
}

// Towards a point 0.5 m ahead on the commanded polyline (its end at the last), at its speed.
void Stepper::walk_polyline(const PedestrianCommand& cmd, double v_des, double dt) {
  const double v = cmd.speed ? v_des : walker_ahead_speed(v_des);
  const WalkStep m = step_along(s.traj_path, s.x, s.y, s.yaw, v, dt);
  s.yaw_rate = std::remainder(m.yaw - s.yaw, 2 * M_PI) / dt;
  s.x = m.x;
  s.y = m.y;
  s.yaw = m.yaw;
  s.walked += m.moved;
  s.acc = (m.moved / dt - s.v) / dt;
  s.v = m.moved / dt;
}

// The farthest arc it may be at: its path's end, or where the next crossing lets it go (the
// curb while it waits; on the road, where the vehicles let it).
double Stepper::crossing_limit_now(double v_des, double dt) {
  return path_limit(
      s.path, s.arc, v_des, dt, s.committed, {d.stop_distance, d.step_back_distance},
      [&](const WalkCrossing& c) { return lights_allow(c) && gap_accepted(threats(c), d.gap); },
      [&](const WalkCrossing& c) { return threats(c); });
}

// Along its path: stopped or stepping back for the road, at its pace (or the commanded one).
void Stepper::walk_path(const std::optional<PedestrianCommand>& cmd, double v_des, double dt) {
  const double limit = crossing_limit_now(v_des, dt);
  double v = 0;
  if (s.idle) {
    v = 0;
  } else if (cmd && cmd->speed) {
    // Commanded: on along its path at that speed, whatever the traffic.
    v = std::min(v_des, (s.path.length() - s.arc) / dt);
    for (size_t i = 0; i < s.path.road_crossings.size(); ++i) {
      const WalkCrossing& c = s.path.road_crossings[i];
      if (c.exit > c.enter && c.enter - kCurbWait <= s.arc + v * dt && c.exit > s.arc) {
        s.committed = i;  // on it: the AI finishes the crossing
        break;
      }
    }
  } else if (limit < s.arc - 1e-9) {
    v = -std::min(v_des, (s.arc - limit) / dt);  // stepping back
  } else {
    v = std::min(v_des, (limit - s.arc) / dt);
    v = std::min(v, walker_ahead_speed(v));
  }
  s.arc = std::max(0.0, s.arc + v * dt);
  s.walked += std::abs(v) * dt;
  s.acc = (v - s.v) / dt;
  s.v = v;
  const odr::Pose2 p = s.path.at(s.arc);
  const double yaw_new = s.idle ? s.yaw : p.heading;
  s.yaw_rate = std::remainder(yaw_new - s.yaw, 2 * M_PI) / dt;
  // Keeps right, so oncoming walkers pass (on a new path from where it stood, easing over).
  if (s.arc > s.kr_from) s.kr = std::min(kKeepRight, s.kr + 0.25 * std::abs(v) * dt);
  s.x = p.x + s.kr * std::sin(p.heading);
  s.y = p.y - s.kr * std::cos(p.heading);
  s.yaw = yaw_new;
  arrive();
}

// At its path's end: standing there (no sidewalk on), or absent (waiting at its start to
// respawn).
void Stepper::arrive() {
  if (!s.idle && s.stand_at_end && s.arc >= s.path.length() - 1e-6) {
    s.idle = true;  // no sidewalk to go on to: it stands where its route ended
  } else if (!s.idle && s.arc >= s.path.length() - 1e-6) {
    s.absent = true;
    s.absent_since_ns = s.time_ns;
    if (d.respawn) {  // absent, it waits at its start: its view is around there
      const odr::Pose2 p0 = d.initial_path.at(0);
      s.x = p0.x + kKeepRight * std::sin(p0.heading);
      s.y = p0.y - kKeepRight * std::cos(p0.heading);
      s.yaw = p0.heading;
    }
    s.v = s.acc = s.yaw_rate = 0;
  }
}

bool Stepper::lights_allow(const WalkCrossing& c) {
  if (!d.obey_lights || (c.ped_signals.empty() && c.veh_signals.empty())) return true;
  if (!s.lights) {
    warn_once("no-lights", "no '" + d.lights_key + "' datapack yet: crosswalk " + c.crosswalk +
                               " treated as unsignalised");
    return true;
  }
  auto state = [&](const std::string& id) -> std::string {
    auto it = s.lights->find(id);
    return it != s.lights->end() ? it->second : std::string();
  };
  std::vector<std::string> ped, veh;
  for (const auto& id : c.ped_signals) ped.push_back(state(id));
  for (const auto& id : c.veh_signals) veh.push_back(state(id));
  return walker_lights_allow(ped, veh);
}

// The pace it may walk at with other walkers ahead: one in its way (within its body's width
// of its line, going its way or standing) closer than kFollowGap is not overtaken.
double Stepper::walker_ahead_speed(double v) const {
  if (!s.neighbours) return v;
  for (const Neighbour& u : s.neighbours->walkers)
    v = pace_behind(s.x, s.y, s.yaw, u.x, u.y, u.yaw, u.speed, v, kFollowGap);
  return v;
}

std::vector<CrossingThreat> Stepper::threats(const WalkCrossing& c) const {
  std::vector<CrossingThreat> out;
  if (!s.neighbours) return out;
  const odr::Pose2 a = s.path.at(c.start), b = s.path.at(c.end);
  const double ex = b.x - a.x, ey = b.y - a.y;
  const double len = std::hypot(ex, ey);
  if (len < 1e-6) return out;
  const CrossingLeg leg{a.x, a.y, ex / len, ey / len, len};
  for (const Neighbour& u : s.neighbours->vehicles) {
    if (std::hypot(u.x - s.x, u.y - s.y) > d.radius) continue;
    const CrossingVehicle v{u.x, u.y, u.yaw, u.speed, u.length, u.width, u.length_offset};
    if (const auto t = crossing_threat(leg, v)) out.push_back(*t);
  }
  return out;
}

void Stepper::replan(const Points& via) {
  WalkPath path;
  s.kr_from = INFINITY;
  s.stand_at_end = !walk_through(*d.graph, path, s.x, s.y, s.yaw, via, d.dest, s.rng, &s.kr_from);
  if (s.stand_at_end && via.empty()) {
    char where[96];
    std::snprintf(where, sizeof where, "(%.2f, %.2f)", s.x, s.y);
    warn_once("idle", std::string("no sidewalk within 50 m of ") + where +
                          ": it stands there until commanded");
  }
  s.path = std::move(path);
  s.idle = s.path.length() < 1e-6;
  s.arc = 0;
  s.kr = 0;
  // Already on the road where the path starts: it is crossing, it does not wait.
  s.committed = SIZE_MAX;
  for (size_t i = 0; i < s.path.road_crossings.size(); ++i) {
    if (s.path.road_crossings[i].enter - kCurbWait <= 1e-9) s.committed = i;
    break;
  }
}

void Stepper::set_polyline(const Points& points) {
  if (points == s.polyline) return;
  s.polyline = points;
  s.traj_path = polyline_walk(points, s.yaw);
}

}  // namespace
}  // namespace convoy::road_users
