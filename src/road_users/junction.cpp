#include "road_users/junction.h"

#include <algorithm>
#include <cmath>

#include "road_users/eta.h"

namespace convoy::road_users {
namespace {

constexpr double kCommitReaction = 1.0;  // s
constexpr double kCommitDecel = 2.0;     // m/s^2

}  // namespace

double junction_wait(const opendrive::LaneGraph& graph, const Approach& at, const Observer& me,
                     const Neighbours& around, const LightStates* lights) {
  const Path& path = *at.path;
  const Path::Crossing* next = nullptr;
  for (const auto& c : path.crossings) {
    if (c.exit > at.front - at.length) {
      next = &c;
      break;
    }
  }
  if (!next) return INFINITY;
  const double v = me.speed, a = at.idm.a, v0 = at.idm.v0;
  const double g = next->enter - at.front;
  if (g < 0 || g > me.radius) return INFINITY;          // inside already, or far
  if (g < v * v / (2 * at.max_decel)) return INFINITY;  // cannot stop before it: committed
  const double my_eta = eta(g, v, a, v0);
  // Until my rear has left the junction.
  const double my_clear = eta(g + (next->exit - next->enter) + at.length, v, a, v0);
  const size_t lo = at.cursor > 40 ? at.cursor - 40 : 0;
  const double c = std::cos(me.yaw), s = std::sin(me.yaw);
  const double my_arc = at.cursor < path.arc.size() ? path.arc[at.cursor] : 0;
  for (const Neighbour& u : around) {
    if (std::hypot(u.x - me.x, u.y - me.y) > me.radius) continue;
    // On my own path (a leader or follower): IDM's business. (The hint: where it would be on a
    // straight path.)
    const double ahead = (u.x - me.x) * c + (u.y - me.y) * s;
    const auto pr = path.project(u.x, u.y, lo, SIZE_MAX, path.index_at(my_arc + ahead));
    if (std::isfinite(pr.d2) && std::abs(pr.lateral) < 1.2 &&
        std::abs(std::remainder(u.yaw - path.at(pr.arc).heading, 2 * M_PI)) < 0.5)
      continue;
    const auto loc = graph.locate(u.x, u.y, u.yaw);
    if (!loc) continue;
    const opendrive::LaneNode& ln = graph.lane(loc->lane);
    const double u_front = u.length_offset + 0.5 * u.length;
    if (ln.junction == next->junction) {
      // Inside; blocking unless its back has nearly left (it is leaving).
      return std::max(g, 0.0);
    }
    // Approaching: its lane leads into the junction.
    bool leads = false;
    for (opendrive::LaneIndex nx : graph.successors(loc->lane)) {
      if (graph.lane(nx).junction == next->junction) leads = true;
    }
    if (!leads) continue;
    const double front_s = ln.forward ? loc->s + u_front : loc->s - u_front;
    if (lights && red_for(graph, *lights, loc->lane, front_s)) continue;  // it waits there
    const double remaining = (ln.forward ? ln.s1 - loc->s : loc->s - ln.s0) - u_front;
    if (remaining < 0) return std::max(g, 0.0);  // its front is in
    const double other_eta = eta(remaining, u.speed, a, v0);
    if (other_eta < my_eta - 0.05 || (other_eta <= my_eta + 0.05 && u.id < me.id))
      return std::max(g, 0.0);
    // I would be first, but one that cannot stop comfortably before the junction any more
    // (1 s to react, then 2 m/s^2) and arrives before I have cleared it does not yield,
    // whoever drives it (SUMO's vehicles keep their right of way): wait for it.
    const double uv = std::max(u.speed, 0.0);
    if (remaining < uv * kCommitReaction + uv * uv / (2 * kCommitDecel) &&
        other_eta < my_clear + 0.5)
      return std::max(g, 0.0);
  }
  return INFINITY;
}

}  // namespace convoy::road_users
