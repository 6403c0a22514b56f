#include "road_users/neighbours.h"

#include <cmath>

namespace convoy::road_users {

LaneNeighbour leader_on(const Path& path, size_t cursor, double front, double pose_spacing,
                        const Observer& me, const Neighbours& around) {
  LaneNeighbour leader;
  const size_t hi = cursor + static_cast<size_t>(me.radius / pose_spacing) + 2;
  const size_t lo = cursor > 10 ? cursor - 10 : 0;
  const double c = std::cos(me.yaw), s = std::sin(me.yaw);
  for (const Neighbour& u : around) {
    if (std::hypot(u.x - me.x, u.y - me.y) > me.radius) continue;
    // Where it would be on a straight path: a hint for the projection.
    const long ahead = std::lround(((u.x - me.x) * c + (u.y - me.y) * s) / pose_spacing);
    const long hint = static_cast<long>(cursor) + ahead;
    const auto pr = path.project(u.x, u.y, lo, hi, hint > 0 ? static_cast<size_t>(hint) : 0);
    if (!std::isfinite(pr.d2)) continue;
    const double half_w = 0.5 * (u.width > 0 ? u.width : 1.8);
    if (std::abs(pr.lateral) > 1.0 + half_w) continue;  // not in my lane
    const double rear = pr.arc + u.length_offset - 0.5 * u.length;
    const double u_front = pr.arc + u.length_offset + 0.5 * u.length;
    if (u_front <= front) continue;  // behind (or beside) me
    const double g = rear - front;
    if (g < leader.gap) leader = {true, g, u.speed};
  }
  return leader;
}

LaneNeighbours lane_neighbours(const Observer& me, const Neighbours& around, double centre,
                               double half_width, double front, double rear) {
  LaneNeighbours near;
  const double c = std::cos(me.yaw), s = std::sin(me.yaw);
  for (const Neighbour& u : around) {
    const double dx = u.x - me.x, dy = u.y - me.y;
    const double lon = dx * c + dy * s, lat = -dx * s + dy * c;
    if (std::abs(lon) > me.radius || std::abs(lat - centre) > half_width) continue;
    const double u_front = lon + u.length_offset + 0.5 * u.length;
    const double u_rear = lon + u.length_offset - 0.5 * u.length;
    if (u_front > front && u_rear > rear) {
      const double g = u_rear - front;
      if (g < near.leader.gap) near.leader = {true, g, u.speed};
    } else {
      const double g = rear - u_front;
      if (g < near.follower.gap) near.follower = {true, g, u.speed};
    }
  }
  return near;
}

bool start_free(const Neighbours& around, double x, double y, double clearance) {
  for (const Neighbour& u : around) {
    if (std::hypot(u.x - x, u.y - y) < clearance) return false;
  }
  return true;
}

}  // namespace convoy::road_users
