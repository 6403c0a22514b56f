#include "road_users/bicycle.h"

#include <cmath>

namespace convoy::road_users {

BicycleMotion step_bicycle(const KinematicBicycle& bicycle, const PlanarPose& pose, double v,
                           double steer, double dt) {
  BicycleMotion m;
  m.yaw_rate = v * std::tan(steer) / bicycle.wheelbase;
  const double yaw_mid = pose.yaw + 0.5 * m.yaw_rate * dt;
  m.pose.x = pose.x + v * std::cos(yaw_mid) * dt;
  m.pose.y = pose.y + v * std::sin(yaw_mid) * dt;
  m.pose.yaw = std::remainder(pose.yaw + m.yaw_rate * dt, 2 * M_PI);
  return m;
}

}  // namespace convoy::road_users
