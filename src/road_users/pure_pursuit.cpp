#include "road_users/pure_pursuit.h"

#include <algorithm>
#include <cmath>

namespace convoy::road_users {

double PurePursuit::lookahead(double v) const {
  return std::max(min_lookahead, lookahead_gain * v + lookahead_offset);
}

double PurePursuit::steer(const PlanarPose& pose, double tx, double ty, double wheelbase) const {
  const double dx = tx - pose.x, dy = ty - pose.y;
  const double alpha = std::atan2(dy, dx) - pose.yaw;
  const double ld = std::max(std::hypot(dx, dy), 1.0);
  const double steer = std::atan2(2.0 * wheelbase * std::sin(alpha), ld);
  return std::clamp(steer, -max_steer, max_steer);
}

opendrive::Pose2 pursuit_target(const Path& path, double a, bool beyond_end) {
  opendrive::Pose2 target = path.at(a);
  if (beyond_end && a > path.length()) {  // past its end: straight on
    target.x += (a - path.length()) * std::cos(target.heading);
    target.y += (a - path.length()) * std::sin(target.heading);
  }
  return target;
}

double pursue(const PurePursuit& pursuit, const KinematicBicycle& bicycle, const Path& path,
              double arc, const PlanarPose& pose, double v, bool beyond_end) {
  const double a_t = arc + bicycle.wheelbase + pursuit.lookahead(v);
  const opendrive::Pose2 target = pursuit_target(path, a_t, beyond_end);
  return pursuit.steer(pose, target.x, target.y, bicycle.wheelbase);
}

}  // namespace convoy::road_users
