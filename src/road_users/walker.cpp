#include "road_users/walker.h"

#include <algorithm>
#include <cmath>

namespace convoy::road_users {

std::optional<CrossingThreat> crossing_threat(const CrossingLeg& leg, const CrossingVehicle& v) {
  const double ux = leg.ux, uy = leg.uy;
  const double dx = std::cos(v.yaw), dy = std::sin(v.yaw);
  const double denom = dx * uy - dy * ux;          // cross(dir, e)
  if (std::abs(denom) < 0.2) return std::nullopt;  // moving along the crossing, not across it
  const double lo = v.length_offset + 0.5 * v.length;
  const double fx = v.x + lo * dx, fy = v.y + lo * dy;  // its front
  const double wx = leg.ax - fx, wy = leg.ay - fy;
  const double tau = (wx * uy - wy * ux) / denom;    // along its heading to the line
  const double along = (wx * dy - wy * dx) / denom;  // where on the line (from a), m
  CrossingThreat t;
  t.half_width = 0.5 * (v.width > 0 ? v.width : 1.8);
  if (along < -t.half_width - 1.0 || along > leg.len + t.half_width + 1.0) return std::nullopt;
  if (tau < -std::max(v.length, 1.0)) return std::nullopt;  // its back has passed
  t.front = tau;
  t.u = along;
  t.speed = v.speed;
  t.tta = tau <= 0 ? 0.0 : (v.speed > 0.05 ? tau / v.speed : INFINITY);
  return t;
}

bool gap_accepted(const std::vector<CrossingThreat>& threats, double gap) {
  bool ok = true;
  for (const CrossingThreat& t : threats) {
    if (t.tta < gap) ok = false;
  }
  return ok;
}

bool walker_lights_allow(const std::vector<std::string>& ped_states,
                         const std::vector<std::string>& veh_states) {
  bool known = false;
  for (const std::string& st : ped_states) {
    if (st.empty() || st == "off") continue;
    known = true;
    if (st != "green") return false;
  }
  if (known) return true;
  for (const std::string& st : veh_states) {
    if (st.empty() || st == "off") continue;
    if (st != "red") return false;  // the traffic it crosses may move
  }
  return true;
}

double crossing_limit(const std::vector<CrossingThreat>& threats, double start, double arc,
                      double v_des, const CrossingCaution& caution, double limit) {
  const double my_u = arc - start;
  for (const CrossingThreat& t : threats) {
    const bool over = t.front <= 0;        // its body is over the crossing line
    if (!over && t.speed < 0.5) continue;  // standing before the line
    const double lo = t.u - t.half_width - 0.5, hi = t.u + t.half_width + 0.5;
    if (my_u > lo && my_u < hi) {
      // In its lane: back out when the vehicle is within step_back_distance, or when it would
      // arrive before it could clear the lane forwards and backing out is shorter.
      const double t_fwd = (hi - my_u) / v_des, t_back = (my_u - lo) / v_des;
      if (!over &&
          (t.front < caution.step_back_distance || (t.tta < t_fwd + 0.5 && t_back < t_fwd)))
        limit = std::min(limit, start + lo - 0.2);
    } else if (my_u <= lo && lo - my_u < 1.5 &&
               (over || t.front < caution.stop_distance || t.tta < (hi - my_u) / v_des + 1.0)) {
      limit = std::min(limit, std::max(arc, start + lo - 0.2));  // wait before it
    }
  }
  return limit;
}

double path_limit(const WalkPath& path, double arc, double v_des, double dt, size_t& committed,
                  const CrossingCaution& caution, const CrossingCheck& may_step_on,
                  const CrossingThreats& threats) {
  double limit = path.length();
  size_t ci = SIZE_MAX;  // the next crossing not yet behind it
  for (size_t i = 0; i < path.road_crossings.size(); ++i) {
    if (path.road_crossings[i].exit > arc + 1e-9 &&
        path.road_crossings[i].exit > path.road_crossings[i].enter) {
      ci = i;
      break;
    }
  }
  if (ci == SIZE_MAX) return limit;
  const WalkCrossing& c = path.road_crossings[ci];
  const double wait_at = c.enter - kCurbWait;
  if (committed != ci && arc >= wait_at - 3.0) {
    const bool ok = may_step_on(c);
    if (ok && arc >= wait_at - v_des * dt - 1e-6) committed = ci;
    if (!ok) limit = std::min(limit, wait_at);
  }
  if (committed == ci) limit = crossing_limit(threats(c), c.start, arc, v_des, caution, limit);
  return limit;
}

double pace_behind(double x, double y, double yaw, double ux, double uy, double uyaw, double uspeed,
                   double v, double follow_gap) {
  const double c = std::cos(yaw), sn = std::sin(yaw);
  const double dx = ux - x, dy = uy - y;
  const double lon = dx * c + dy * sn, lat = -dx * sn + dy * c;
  if (lon <= 0 || lon > follow_gap + 0.5 || std::abs(lat) > 0.6) return v;
  const double along = uspeed * std::cos(uyaw - yaw);
  if (along < -0.1) return v;  // coming towards it: they pass each other on the right
  return lon < follow_gap ? std::min(v, std::max(0.0, along)) : v;
}

}  // namespace convoy::road_users
